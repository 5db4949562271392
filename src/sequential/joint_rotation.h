#pragma once
// The rotation of the minimum joint-angle rule (metric_rules.cc) and of its contact sweep
// (contact_sweep.cc): one function, so that both compute it with the same operations.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace flexkin::internal {

// The rotation taking direction u to direction v: in 2D by the signed angle between them; in 3D
// the smallest one (Eigen's Quaternion::FromTwoVectors; for an exact reversal it picks an axis
// perpendicular to u).
template <int Dim>
Eigen::Matrix<double, Dim, Dim> RotationBetween(const Eigen::Matrix<double, Dim, 1>& u,
                                                const Eigen::Matrix<double, Dim, 1>& v) {
  if constexpr (Dim == 2) {
    return Eigen::Rotation2Dd(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v)))
        .toRotationMatrix();
  } else {
    return Eigen::Quaterniond::FromTwoVectors(u, v).toRotationMatrix();
  }
}

}  // namespace flexkin::internal

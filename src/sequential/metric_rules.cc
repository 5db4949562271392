// The sequential rules of the paper's other two metrics (Sec. 4.1 and 4.2), applied sub-step by
// sub-step as the leading end moves in a straight line:
//  - minimum rotation: for one link, the tail position that rotates the link least (zero
//    rotation) is the old tail moved by the head's displacement, so the whole chain translates;
//  - minimum joint-angle change: the first link has no joint before it and moves by the tractrix
//    (L2) step; every later link keeps its angle to the link before it, so it turns with that
//    link: the chain behind the first link moves rigidly with it. In 3D the rotations keeping a
//    joint angle are not unique; the rule applies the smallest rotation taking the first link's
//    old direction to its new one (Eigen's Quaternion::FromTwoVectors; for an exact reversal it
//    picks an axis perpendicular to the link).

#include <Eigen/Geometry>

#include "sequential/link_rules.h"
#include "sequential/sweep.h"

namespace flexkin::internal {

void SweepsMinRotation(int dim, const double* heads, int64_t num_sweeps, int n, double* points) {
  for (int64_t s = 0; s < num_sweeps; ++s) {
    for (int k = 0; k < dim; ++k) {
      const double shift = heads[s * dim + k] - points[k];
      for (int i = 0; i <= n; ++i) points[i * dim + k] += shift;
    }
  }
}

namespace {

template <int Dim>
void MinJointAngle(const double* heads, int64_t num_sweeps, const double* lengths,
                   const double* inv_lengths, int n, double* points) {
  using Vec = Eigen::Matrix<double, Dim, 1>;
  Eigen::Map<Eigen::Matrix<double, Dim, Eigen::Dynamic>> p(points, Dim, n + 1);
  for (int64_t s = 0; s < num_sweeps; ++s) {
    const Vec head_old = p.col(0), first_old = p.col(1);
    const Vec head_new = Eigen::Map<const Vec>(heads + s * Dim);
    Vec first_new = first_old;
    TractrixStep<Dim>(head_old.data(), head_new.data(), first_new.data(), lengths[0],
                      inv_lengths[0]);
    const Vec u = first_old - head_old, v = first_new - head_new;
    Eigen::Matrix<double, Dim, Dim> rotation;
    if constexpr (Dim == 2) {
      rotation = Eigen::Rotation2Dd(std::atan2(u.x() * v.y() - u.y() * v.x(), u.dot(v)))
                     .toRotationMatrix();
    } else {
      rotation = Eigen::Quaterniond::FromTwoVectors(u, v).toRotationMatrix();
    }
    for (int i = 2; i <= n; ++i) p.col(i) = first_new + rotation * (p.col(i) - first_old);
    p.col(0) = head_new;
    p.col(1) = first_new;
  }
}

}  // namespace

void SweepsMinJointAngle(int dim, const double* heads, int64_t num_sweeps, const double* lengths,
                         const double* inv_lengths, int n, double* points) {
  dim == 2 ? MinJointAngle<2>(heads, num_sweeps, lengths, inv_lengths, n, points)
           : MinJointAngle<3>(heads, num_sweeps, lengths, inv_lengths, n, points);
}

}  // namespace flexkin::internal

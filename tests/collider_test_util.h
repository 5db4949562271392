#pragma once
// The colliders and measurements the collider tests share: shapes placed by hand, and the least
// distance of a link to a collider sampled along it with QuerySurface (independent of the segment
// clearances the runs use).

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "flexkin/chain.h"
#include "flexkin/colliders.h"

namespace flexkin::collider_test {

inline Collider Sphere(const Eigen::Vector3d& center, double radius) {
  Collider c;
  c.shape = ColliderShape::kSphere;
  c.pose.translation() = center;
  c.radius = radius;
  return c;
}

// A capsule about `center` along the z axis.
inline Collider Capsule(const Eigen::Vector3d& center, double radius, double half_length) {
  Collider c;
  c.shape = ColliderShape::kCapsule;
  c.pose.translation() = center;
  c.radius = radius;
  c.half_length = half_length;
  return c;
}

// A capsule about the segment from `from` to `to`.
inline Collider CapsuleBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                               double radius) {
  Collider c;
  c.shape = ColliderShape::kCapsule;
  c.pose.translation() = 0.5 * (from + to);
  c.pose.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), to - from).matrix();
  c.half_length = 0.5 * (to - from).norm();
  c.radius = radius;
  return c;
}

inline Collider Box(const Eigen::Vector3d& center, const Eigen::Vector3d& half) {
  Collider c;
  c.shape = ColliderShape::kBox;
  c.pose.translation() = center;
  c.extents = half;
  return c;
}

// Point i of `p` (2D or 3D) in 3D.
inline Eigen::Vector3d At(const Points& p, Eigen::Index i) {
  return Eigen::Vector3d(p(i, 0), p(i, 1), p.cols() == 3 ? p(i, 2) : 0.0);
}

// The least signed distance of the link [a, b] to `c` (grown by its margin), at `samples` + 1
// evenly spaced points.
inline double SampledDistance(const Collider& c, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              int samples = 2000) {
  double least = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= samples; ++i) {
    least = std::fmin(least,
                      QuerySurface(c, a + (static_cast<double>(i) / samples) * (b - a)).distance);
  }
  return least;
}

}  // namespace flexkin::collider_test

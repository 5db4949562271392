// The colliders' geometry (flexkin/colliders.h) against FCL, the collision library robotics uses,
// and against properties that do not depend on any library: outside, the signed distance and the
// nearest point equal FCL's for every shape, placed by a random pose; inside and outside, the
// nearest point lies on the surface (the shape's implicit equation), its distance to the point is
// the distance reported, no point of a dense sample of the surface is nearer, and the normal is
// the surface's (or the direction to the point).
#include "flexkin/colliders.h"

#include <fcl/fcl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace flexkin {
namespace {

using Eigen::Vector3d;

Eigen::Isometry3d RandomPose(std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  q.normalize();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Vector3d(normal(*rng), normal(*rng), normal(*rng));
  return pose;
}

std::vector<Collider> Shapes(std::mt19937* rng) {
  std::vector<Collider> shapes;
  Collider c;
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kSphere;
  c.radius = 0.7;
  shapes.push_back(c);
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kCapsule;
  c.radius = 0.4;
  c.half_length = 0.9;
  shapes.push_back(c);
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kCylinder;
  c.radius = 0.5;
  c.half_length = 0.6;
  shapes.push_back(c);
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kBox;
  c.extents = Vector3d(0.3, 0.8, 0.5);
  shapes.push_back(c);
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kEllipsoid;
  c.extents = Vector3d(0.9, 0.4, 0.6);
  shapes.push_back(c);
  c.pose = RandomPose(rng);
  c.shape = ColliderShape::kHalfSpace;
  shapes.push_back(c);
  return shapes;
}

// The shape as FCL has it: FCL's capsule, cylinder and box take full lengths. FCL computes no
// distance to its half-space (fcl#392: its maintainers' workaround is a box), so the half-space is
// a box of side 1000 whose top face is z = 0, far larger than the points' distances.
std::shared_ptr<fcl::CollisionGeometryd> FclShape(const Collider& c) {
  switch (c.shape) {
    case ColliderShape::kSphere:
      return std::make_shared<fcl::Sphered>(c.radius);
    case ColliderShape::kEllipsoid:
      return std::make_shared<fcl::Ellipsoidd>(c.extents.x(), c.extents.y(), c.extents.z());
    case ColliderShape::kCapsule:
      return std::make_shared<fcl::Capsuled>(c.radius, 2.0 * c.half_length);
    case ColliderShape::kCylinder:
      return std::make_shared<fcl::Cylinderd>(c.radius, 2.0 * c.half_length);
    case ColliderShape::kBox:
      return std::make_shared<fcl::Boxd>(2.0 * c.extents);
    case ColliderShape::kHalfSpace:
      return std::make_shared<fcl::Boxd>(1000.0, 1000.0, 1000.0);
  }
  return nullptr;
}

// The value of the shape's implicit function at a local point, scaled to be a distance near the
// surface (0 on it).
double Implicit(const Collider& c, const Vector3d& p) {
  switch (c.shape) {
    case ColliderShape::kSphere:
      return p.norm() - c.radius;
    case ColliderShape::kEllipsoid:
      return (p.cwiseQuotient(c.extents).norm() - 1.0) * c.extents.minCoeff();
    case ColliderShape::kCapsule:
      return (p - Vector3d(0, 0, std::clamp(p.z(), -c.half_length, c.half_length))).norm() -
             c.radius;
    case ColliderShape::kCylinder: {
      const double side = std::hypot(p.x(), p.y()) - c.radius;
      const double cap = std::fabs(p.z()) - c.half_length;
      return std::fmax(side, cap) > 0.0 && side > 0.0 && cap > 0.0 ? std::hypot(side, cap)
                                                                   : std::fmax(side, cap);
    }
    case ColliderShape::kBox: {
      const Vector3d beyond = p.cwiseAbs() - c.extents;
      return beyond.maxCoeff() <= 0.0 ? beyond.maxCoeff() : beyond.cwiseMax(0.0).norm();
    }
    case ColliderShape::kHalfSpace:
      return p.z();
  }
  return 0.0;
}

// A dense sample of the shape's surface (local), for the brute-force nearest point.
std::vector<Vector3d> SurfaceSample(const Collider& c) {
  std::vector<Vector3d> points;
  constexpr int kN = 160;
  for (int i = 0; i <= kN; ++i) {
    for (int j = 0; j < 2 * kN; ++j) {
      const double u = M_PI * i / kN, v = M_PI * j / kN;  // polar, azimuth
      const Vector3d dir(std::sin(u) * std::cos(v), std::sin(u) * std::sin(v), std::cos(u));
      switch (c.shape) {
        case ColliderShape::kSphere:
          points.push_back(c.radius * dir);
          break;
        case ColliderShape::kEllipsoid:
          points.push_back(c.extents.cwiseProduct(dir));
          break;
        case ColliderShape::kCapsule:
          points.push_back(c.radius * dir +
                           Vector3d(0, 0, dir.z() >= 0.0 ? c.half_length : -c.half_length));
          points.push_back(Vector3d(c.radius * std::cos(v), c.radius * std::sin(v),
                                    c.half_length * (2.0 * i / kN - 1.0)));
          break;
        case ColliderShape::kCylinder: {
          const double t = static_cast<double>(i) / kN;
          points.push_back(Vector3d(c.radius * std::cos(v), c.radius * std::sin(v),
                                    c.half_length * (2.0 * t - 1.0)));
          points.push_back(
              Vector3d(t * c.radius * std::cos(v), t * c.radius * std::sin(v), c.half_length));
          points.push_back(
              Vector3d(t * c.radius * std::cos(v), t * c.radius * std::sin(v), -c.half_length));
          break;
        }
        case ColliderShape::kBox: {
          const double a = 2.0 * i / kN - 1.0, b = static_cast<double>(j) / kN - 1.0;
          for (int axis = 0; axis < 3; ++axis) {
            for (double side : {-1.0, 1.0}) {
              Vector3d p;
              p[axis] = side;
              p[(axis + 1) % 3] = a;
              p[(axis + 2) % 3] = b;
              points.push_back(c.extents.cwiseProduct(p));
            }
          }
          break;
        }
        case ColliderShape::kHalfSpace:
          points.push_back(Vector3d(4.0 * (2.0 * i / kN - 1.0), 4.0 * (j / double(kN) - 1.0), 0));
          break;
      }
    }
  }
  return points;
}

TEST(CollidersTest, OutsideTheDistanceAndNearestPointAreFcls) {
  std::mt19937 rng(26);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (int round = 0; round < 20; ++round) {
    for (const Collider& c : Shapes(&rng)) {
      ASSERT_TRUE(CheckCollider(c, "/c").empty());
      const Eigen::Isometry3d placed =
          c.shape == ColliderShape::kHalfSpace ? c.pose * Eigen::Translation3d(0, 0, -500) : c.pose;
      fcl::CollisionObjectd object(FclShape(c), fcl::Transform3d(placed));
      for (int t = 0; t < 20; ++t) {
        const Vector3d x =
            c.pose.translation() + 2.0 * Vector3d(normal(rng), normal(rng), normal(rng));
        const SurfaceQuery q = QuerySurface(c, x);
        if (q.distance < 0.05) continue;  // FCL's distance is for separated shapes
        // A ball of radius r at x is d - r from a convex shape when d > r.
        constexpr double kR = 1e-3;
        fcl::CollisionObjectd probe(std::make_shared<fcl::Sphered>(kR),
                                    fcl::Transform3d(Eigen::Translation3d(x)));
        fcl::DistanceRequestd request;
        request.enable_nearest_points = true;
        request.gjk_solver_type = fcl::GST_INDEP;
        request.distance_tolerance = 1e-12;
        fcl::DistanceResultd result;
        fcl::distance(&object, &probe, request, result);
        SCOPED_TRACE(std::string(ColliderShapeName(c.shape)) + " round " + std::to_string(round));
        // FCL's GJK (ellipsoid, cylinder) is exact to its tolerance, about 1e-6 relative.
        const double tolerance =
            c.shape == ColliderShape::kEllipsoid || c.shape == ColliderShape::kCylinder ? 1e-5
                                                                                        : 1e-9;
        EXPECT_NEAR(q.distance, result.min_distance + kR, tolerance * (1.0 + q.distance));
        EXPECT_LE((q.nearest - result.nearest_points[0]).norm(), 1e2 * tolerance)
            << "ours " << q.nearest.transpose() << " fcl " << result.nearest_points[0].transpose();
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 1000);
}

TEST(CollidersTest, TheNearestPointIsOnTheSurfaceAndNoSampleIsNearer) {
  std::mt19937 rng(2026);
  std::normal_distribution<double> normal;
  int inside = 0, outside = 0;
  for (int round = 0; round < 3; ++round) {
    for (const Collider& c : Shapes(&rng)) {
      const std::vector<Vector3d> sample = SurfaceSample(c);
      for (int t = 0; t < 25; ++t) {
        const Vector3d local = 0.8 * Vector3d(normal(rng), normal(rng), normal(rng));
        const Vector3d x = c.pose * local;
        const SurfaceQuery q = QuerySurface(c, x);
        SCOPED_TRACE(std::string(ColliderShapeName(c.shape)) + " at " + std::to_string(local.x()) +
                     " " + std::to_string(local.y()) + " " + std::to_string(local.z()));
        const Vector3d nearest_local = c.pose.inverse() * q.nearest;
        EXPECT_NEAR(Implicit(c, nearest_local), 0.0, 1e-13);
        EXPECT_NEAR(std::fabs(q.distance), (x - q.nearest).norm(), 1e-13);
        EXPECT_EQ(q.distance < 0.0, Implicit(c, local) < 0.0);
        EXPECT_NEAR(q.normal.norm(), 1.0, 1e-14);
        if (std::fabs(q.distance) > 1e-9) {
          // The normal points from the surface toward an outside point, away from an inside one.
          EXPECT_NEAR(q.normal.dot(x - q.nearest), q.distance, 1e-12);
        }
        (q.distance < 0.0 ? inside : outside) += 1;
        double best = std::numeric_limits<double>::infinity();
        for (const Vector3d& s : sample) best = std::fmin(best, (local - s).norm());
        // The sample is a grid: the nearest sample point is within its spacing of the true one.
        EXPECT_LE(std::fabs(q.distance), best + 1e-12);
        EXPECT_GE(std::fabs(q.distance), best - 0.05);
      }
    }
  }
  EXPECT_GE(inside, 60);
  EXPECT_GE(outside, 60);
}

TEST(CollidersTest, DegenerateCollidersAreRefusedByField) {
  Collider sphere;
  sphere.radius = 0.0;
  auto problems = CheckCollider(sphere, "/colliders/0");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "/colliders/0/radius");
  EXPECT_EQ(problems[0].value, "0");

  Collider box;
  box.shape = ColliderShape::kBox;
  box.extents = Vector3d(1.0, -1.0, std::nan(""));
  problems = CheckCollider(box, "/c");
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].field, "/c/extents/1");
  EXPECT_EQ(problems[1].field, "/c/extents/2");

  Collider skewed;
  skewed.radius = 1.0;
  skewed.pose.linear() << 1, 0.1, 0, 0, 1, 0, 0, 0, 1;
  problems = CheckCollider(skewed, "/c");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].field, "/c/pose");

  Collider mirrored;
  mirrored.radius = 1.0;
  mirrored.pose.linear() = Eigen::Vector3d(1, 1, -1).asDiagonal();
  EXPECT_EQ(CheckCollider(mirrored, "/c").size(), 1u);
}

}  // namespace
}  // namespace flexkin

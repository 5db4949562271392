#pragma once
// Things in the world: the convex colliders a chain, a strand or a robot is to stay outside of
// (docs/colliders.md). This header gives their geometry: what each shape is, how it is placed,
// and where a point stands with respect to it (signed distance, nearest surface point, outward
// normal), in closed form for every shape but the ellipsoid, whose nearest point is the root of
// a monotone function of one variable, found by bisection to the last bit.

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "flexkin/error.h"

namespace flexkin {

enum class ColliderShape {
  kSphere,     // `radius` about the frame's origin
  kEllipsoid,  // semi-axes `extents` along the frame's x, y and z
  kCapsule,    // `radius` about the segment from (0, 0, -half_length) to (0, 0, half_length)
  kCylinder,   // solid, `radius` about the z axis, flat caps at z = +-half_length
  kBox,        // half extents `extents` along x, y and z
  kHalfSpace,  // the solid z <= 0 (a floor whose up is the frame's z axis)
};

// A collider: its shape in its own frame, placed in the world by `pose` (a rotation and a
// translation; world = pose * local).
struct Collider {
  ColliderShape shape = ColliderShape::kSphere;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double radius = 0.0;                                // sphere, capsule, cylinder
  double half_length = 0.0;                           // capsule, cylinder
  Eigen::Vector3d extents = Eigen::Vector3d::Zero();  // box (half extents), ellipsoid (semi-axes)
};

// Where a point stands with respect to a collider's surface.
struct SurfaceQuery {
  double distance = 0.0;  // signed: positive outside, negative inside (minus the depth)
  Eigen::Vector3d nearest = Eigen::Vector3d::Zero();  // the nearest point of the surface
  // The surface's outward unit normal at `nearest` (where the surface has an edge or a corner
  // there, the direction from `nearest` to the point outside, or a face's normal inside).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// The point `x` (world) with respect to `collider`'s surface. `collider` must pass
// CheckCollider.
SurfaceQuery QuerySurface(const Collider& collider, const Eigen::Vector3d& x);

// The problems of a collider, fields named under `field` (e.g. "/colliders/2"): a radius, length
// or extent that is not finite and positive (half_length may be 0: a capsule that is a sphere, a
// cylinder that is a disc is refused), a pose that is not a rotation and a finite translation.
std::vector<Problem> CheckCollider(const Collider& collider, const std::string& field);

// The shape's name in scenarios ("sphere", "ellipsoid", "capsule", "cylinder", "box",
// "half_space").
const char* ColliderShapeName(ColliderShape shape);

}  // namespace flexkin

#pragma once
// Things in the world: the convex colliders a chain, a strand or a robot is to stay outside of
// (docs/colliders.md), and closed triangle meshes. This header gives their geometry: what each
// shape is, how it is placed, and where a point stands with respect to it (signed distance,
// nearest surface point, outward normal), in closed form for every shape but the ellipsoid, whose
// nearest point is the root of a monotone function of one variable, found by bisection to the
// last bit, and the mesh, whose nearest triangle is found through a bounding volume hierarchy.

#include <Eigen/Geometry>
#include <memory>
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
  kMesh,       // the solid a closed triangle mesh bounds (`mesh`), times `scale` (3D only)
};

using MeshVertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  // #V by 3
using MeshTriangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;    // #F by 3

namespace internal {
struct MeshBvh;  // the mesh's bounding volume hierarchy (FCL's), src/world/mesh_collider.h
}  // namespace internal

// A closed triangle mesh (docs/colliders.md, "Meshes"): watertight (every edge shared by exactly
// two triangles), consistently oriented, counter-clockwise seen from outside. Built once by
// MakeColliderMesh or ReadColliderMeshFile and shared by every collider (and copy) that uses it.
struct ColliderMeshData {
  std::string file;         // the file as the scenario wrote it ("" for a mesh given inline)
  MeshVertices vertices;    // in its own frame, unscaled
  MeshTriangles triangles;  // indices into vertices
  double radius = 0.0;      // of the smallest ball about the frame's origin that holds it
  double feature = 0.0;     // the median edge length: the finest detail the contact search resolves
  std::shared_ptr<const internal::MeshBvh> bvh;
};

// A rigid pose: x -> rotation x + translation (a groom's body, a moving collider's frame). In 2D
// the top-left 2x2 block of `rotation` and the first two components of `translation` are used.
// `rotation` must be a rotation (orthonormal, determinant +1) to within 1e-9.
struct BodyPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  // From a unit quaternion (w, x, y, z) (normalized here; it must not be zero) and a translation.
  static BodyPose FromQuaternion(double w, double x, double y, double z,
                                 const Eigen::Vector3d& translation);
  // A planar pose: rotation by `angle` (radians) about z, then the translation (tx, ty).
  static BodyPose Planar(double angle, double tx, double ty);
};

// A keyframe of a rigid motion (a groom's body: time in seconds; a chain scenario's collider:
// time in leader steps).
struct BodyKeyframe {
  double time = 0.0;  // strictly increasing over the keyframes
  BodyPose pose;
};

// How a rigid motion passes between keyframes: the translation interpolated linearly and the
// rotation by slerp (the shorter arc), in the parameter u of the segment (kLinear) or
// 3u^2 - 2u^3 (kSmooth: at rest at every keyframe).
enum class KeyframeInterpolation { kLinear, kSmooth };

// The pose at `time` of the motion through `keyframes` (times strictly increasing): a keyframe's
// own pose at its time (and within 1e-12 of a segment from it), the first keyframe's before it,
// the last's after it, else interpolated as `interpolation` says. No keyframes: the identity.
// A part that does not change between two keyframes stays exactly as it is.
BodyPose InterpolateKeyframes(const std::vector<BodyKeyframe>& keyframes,
                              KeyframeInterpolation interpolation, double time);

// A keyframed collider's motion (docs/colliders.md, "Moving colliders"): at time t the collider's
// own frame (its `pose`) is carried by the pose of the keyframes at t. In a chain run, time is
// counted in leader steps: frame s (after s leader steps) is at time s, sub-step j of m of leader
// step s (1-based) at s - 1 + j / m.
struct ColliderMotion {
  std::vector<BodyKeyframe> keyframes;  // at least 1
  KeyframeInterpolation interpolation = KeyframeInterpolation::kSmooth;
};

// A collider: its shape in its own frame, placed in the world by `pose` (a rotation and a
// translation; world = pose * local).
struct Collider {
  ColliderShape shape = ColliderShape::kSphere;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double radius = 0.0;                                // sphere, capsule, cylinder
  double half_length = 0.0;                           // capsule, cylinder
  Eigen::Vector3d extents = Eigen::Vector3d::Zero();  // box (half extents), ellipsoid (semi-axes)
  // The shape grown by `margin` (>= 0) all round: the set of points within `margin` of it (its
  // Minkowski sum with a ball), which is where the axis of a link of radius `margin` (a rope's,
  // a robot link's capsule) must not go. Signed distances are the shape's less `margin`, exactly:
  // the shape is convex. Runs set it from a link radius (RunOptions::link_radius); 0 in scenario
  // files, which give the shapes as they are.
  double margin = 0.0;
  // kMesh: the mesh in its own frame, scaled by `scale` (> 0) about that frame's origin.
  std::shared_ptr<const ColliderMeshData> mesh;
  double scale = 1.0;
  // Keyframed colliders: the motion that carries `pose` (null: the collider stays where it is).
  // Copies share it.
  std::shared_ptr<const ColliderMotion> motion;
};

// `collider` at `time`: its pose carried by its motion's pose at `time` (motion pose * pose),
// without the motion; a collider without motion is returned as it is.
Collider ColliderAt(const Collider& collider, double time);

// Whether any of `colliders` has a motion.
bool AnyMoves(const std::vector<Collider>& colliders);

// Every one of `colliders` at `time` (ColliderAt).
std::vector<Collider> CollidersAt(const std::vector<Collider>& colliders, double time);

// Where a point stands with respect to a collider's surface.
struct SurfaceQuery {
  double distance = 0.0;  // signed: positive outside, negative inside (minus the depth)
  Eigen::Vector3d nearest = Eigen::Vector3d::Zero();  // the nearest point of the surface
  // The surface's outward unit normal at `nearest` (where the surface has an edge or a corner
  // there, the direction from `nearest` to the point outside, or a face's normal inside).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// The point `x` (world) with respect to `collider`'s surface (grown by its margin). `collider`
// must pass CheckCollider.
SurfaceQuery QuerySurface(const Collider& collider, const Eigen::Vector3d& x);

// The problems of a collider, fields named under `field` (e.g. "/colliders/2"): a radius, length
// or extent that is not finite and positive (half_length may be 0: a capsule that is a sphere, a
// cylinder that is a disc is refused), a margin that is not finite and >= 0, a pose that is not a
// rotation and a finite translation; a motion without keyframes, with times that are not finite
// and strictly increasing, or with a keyframe pose that is not a rotation and a finite
// translation ("field.motion.keyframes[k]...").
std::vector<Problem> CheckCollider(const Collider& collider, const std::string& field);

// A mesh collider's data from its vertices (#V by 3) and triangles (#F by 3, indices into
// vertices). Null, with every problem appended to `problems` (named under `field`, e.g.
// "/colliders/2"), if it is empty, has a vertex that is not finite, an index out of range, a
// triangle with a repeated vertex, an edge not shared by exactly two triangles (an open mesh: how
// many, one of them), or two triangles that run an edge the same way (inconsistent orientation).
// A mesh oriented inside out (negative volume) is turned.
std::shared_ptr<const ColliderMeshData> MakeColliderMesh(MeshVertices vertices,
                                                         MeshTriangles triangles,
                                                         const std::string& file,
                                                         const std::string& field,
                                                         std::vector<Problem>* problems);

// An STL or OBJ file (any format assimp reads) at `path` as a mesh collider's data: its
// triangles, vertices at the same place joined, every mesh of the file in one. `file` is the name
// as written (kept in ColliderMeshData::file). Null, with the problems appended as
// MakeColliderMesh's and: the file missing or unreadable (the system's reason), or not a mesh
// assimp can read (its reason), named by `field` + "/file".
std::shared_ptr<const ColliderMeshData> ReadColliderMeshFile(const std::string& path,
                                                             const std::string& file,
                                                             const std::string& field,
                                                             std::vector<Problem>* problems);

// The shape's name in scenarios ("sphere", "ellipsoid", "capsule", "cylinder", "box",
// "half_space", "mesh").
const char* ColliderShapeName(ColliderShape shape);

}  // namespace flexkin

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
};

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
// rotation and a finite translation.
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

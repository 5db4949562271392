#pragma once
// The colliders as pictures and scenes show them (docs/result-format.md, "colliders"): a
// triangulated surface (glTF, the 3D figures' and the viewer's silhouettes), the outline of a 2D
// collider's section by the plane z = 0 (the 2D figures and the viewer), the plane of a
// half-space within a box, and the bounds the axes must include. One geometry for the render,
// viewer and glTF components, beside the colliders' JSON form (io/colliders_json.h). Private to
// the library.

#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "flexkin/colliders.h"

namespace flexkin {

struct ResultFile;
struct StrandFileHeader;

// A strand file's body colliders (in body coordinates) but the scalp's own (the sphere or
// ellipsoid a groom adds for its scalp, which the pictures shade as the scalp itself): what the
// strand figures and the strands viewer draw beside the scalp, with the world colliders.
std::vector<Collider> BodyCollidersBesideScalp(const StrandFileHeader& header);

// The box [*lo, *hi] that holds every point of every frame of `file` (3D; a 2D file's z is 0).
void BoundsOfMotion(const ResultFile& file, Eigen::Vector3d* lo, Eigen::Vector3d* hi);

// A triangulated surface in world coordinates: every vertex on the collider's surface (to
// rounding), triangles counter-clockwise seen from outside (a half-space's: from the free side).
struct ColliderMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// The surface of a finite collider, `segments` (>= 8) round each round part; a half-space's
// plane as a square of half side `half_size` centred on the point of the plane nearest `center`.
ColliderMesh MeshOfCollider(const Collider& collider, int segments, const Eigen::Vector3d& center,
                            double half_size);

// 2D (a collider passing CollidersProblems in 2D): the outline of its section by the plane z = 0,
// a convex polygon, counter-clockwise, `segments` (>= 8) round each round part; a half-space's
// free-side-clipped part of the rectangle [lo, hi]. Empty where the section is empty (a sphere
// whose centre is farther off the plane than its radius).
std::vector<Eigen::Vector2d> OutlineOfCollider2d(const Collider& collider, int segments,
                                                 const Eigen::Vector2d& lo,
                                                 const Eigen::Vector2d& hi);

// The polygon where a half-space's plane crosses the box [lo, hi] (convex, counter-clockwise seen
// from the free side); empty if it does not.
std::vector<Eigen::Vector3d> HalfSpacePlaneInBox(const Collider& half_space,
                                                 const Eigen::Vector3d& lo,
                                                 const Eigen::Vector3d& hi);

// Grows [lo, hi] to hold a finite collider's bounding box, exactly (in 2D, `dim` 2: x and y only,
// z left alone); of a half-space, its boundary's point nearest `center` and the point 15% of the
// box's extent below it, so that its edge and a band of its solid are in view.
void ExtendByCollider(const Collider& collider, int dim, const Eigen::Vector3d& center,
                      Eigen::Vector3d* lo, Eigen::Vector3d* hi);

// The same for a collider shown with the recorded frames of `file`: a keyframed one wherever it
// is in a frame (ColliderAt the frame's step; at most 256 frames, evenly, and the last).
void ExtendByColliderOverFrames(const Collider& collider, const ResultFile& file, int dim,
                                const Eigen::Vector3d& center, Eigen::Vector3d* lo,
                                Eigen::Vector3d* hi);

// The pose of a keyframed collider's motion at `time` (the identity without a motion): what
// carries its own pose there (ColliderAt).
Eigen::Isometry3d MotionPoseAt(const Collider& collider, double time);

// Per recorded frame f of `file`, M(t_f) M(t_0)^-1 (M: the keyframed collider's MotionPoseAt,
// t_f: frame f's step): the move that carries it from where the first frame has it, as the
// viewer and glTF animate it.
std::vector<Eigen::Isometry3d> MovesFromFirstFrame(const Collider& collider,
                                                   const ResultFile& file);

}  // namespace flexkin

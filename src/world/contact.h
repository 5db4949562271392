#pragma once
// A link against the colliders (docs/colliders.md): the clearance of a segment, and the sequential
// step of a link whose rule would put it into a collider.

#include <Eigen/Core>
#include <vector>

#include "flexkin/colliders.h"

namespace flexkin::internal {

// What a link may lie inside a collider, relative to its length: the rounding of positions
// computed on a surface (a point found on it to the last bit, then the head of the next link).
constexpr double kContactSlack = 1e-13;

// The least signed distance of any point of the segment [a, b] to `collider` (negative: the
// segment enters it, by that depth). Closed form for the sphere, capsule and half-space; for the
// others, the minimum of the signed distance along the segment (a convex function: the collider is
// convex) by golden-section search to the last bits of the parameter; a mesh, not convex, by its
// distance and crossings (world/mesh_collider.h).
double SegmentClearance(const Collider& collider, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b);

// QuerySurface(collider, x), the same bits, with `to_local` = the collider's pose inverted
// (pose.inverse(Eigen::Isometry)) computed once by the caller: for searches that query one
// collider many times.
SurfaceQuery QuerySurface(const Collider& collider, const Eigen::Isometry3d& to_local,
                          const Eigen::Vector3d& x);

// QuerySurface(collider, x).distance, the same bits, with `to_local` = the collider's pose
// inverted (pose.inverse(Eigen::Isometry)) computed once by the caller, and without the nearest
// point and normal carried back to the world: for searches that query one collider many times.
double SurfaceDistance(const Collider& collider, const Eigen::Isometry3d& to_local,
                       const Eigen::Vector3d& x);

// The radius of a ball about the collider's origin (its pose's translation) that holds it, its
// margin included (0 for a half-space, which no ball holds).
double BoundingRadius(const Collider& collider);

// A lower bound of QuerySurface(collider, x).distance, cheap: exact for a sphere and a
// half-space, else the distance to the ball of BoundingRadius (broad phases).
double DistanceLowerBound(const Collider& collider, const Eigen::Vector3d& x);

// Whether SegmentClearance(collider, a, b) < threshold; for an ellipsoid, a cylinder or a box
// the same answer, from the same golden-section search, stopped where its answer is known (a
// value below the threshold, or a lower bound of the convex function above it), where bounds of
// the signed distance from the shape's gauge along the link (closed form) do not already tell.
//
// With `band` > 0 the answer may also be yes for a link whose clearance is below threshold +
// band but not below the threshold (for an ellipsoid, a cylinder or a box: where the bounds
// tell that, the search is not run); a no is always certain.
bool SegmentClearanceBelow(const Collider& collider, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, double threshold, double band = 0.0);

// The smallest clearance of [a, b] over `colliders` (+inf for none).
double SegmentClearance(const std::vector<Collider>& colliders, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b);

// Where the segment [a, b] comes nearest a collider: the parameter `s` of the point a + s (b - a)
// of least signed distance, that distance (SegmentClearance's value, to the rounding, for a
// convex collider) and the collider's outward normal there (the signed distance's gradient at
// that point). By the envelope theorem the clearance's gradient is (1 - s) normal in a and s
// normal in b. Closed form for the sphere, capsule and half-space; else the zero of the
// distance's slope along the segment (convex: a slope that does not decrease), bisected to the
// last bit; for a mesh (not convex), within the bracket of the least of 33 samples along the
// segment: a local minimum, the nearest where the mesh's features are coarser than the samples.
struct SegmentContact {
  double clearance = 0.0;
  double s = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};
SegmentContact NearestOnSegment(const Collider& collider, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b);

// The sequential step of one link with colliders: its leading end is at `head` (already moved,
// outside every collider); its trailing end was at `tail`. Of the positions x at distance `length`
// from `head` whose link [head, x] stays outside every collider (to kContactSlack), the one
// nearest to `tail` (the
// least motion; direction = the unit direction from head to x, nearest in angle to that of tail).
// In 2D (dim 2, z = 0) the directions are a circle, in 3D a sphere. Returns false if every
// direction is blocked (the head is wedged between colliders), leaving *x alone. `clearance`, if
// given, receives SegmentClearance(colliders, head, *x).
bool ContactTail(int dim, const Eigen::Vector3d& head, const Eigen::Vector3d& tail, double length,
                 const std::vector<Collider>& colliders, Eigen::Vector3d* x,
                 double* clearance = nullptr);

// ContactTail leaves the tail where the link meets the collider to within its slack, or, from a
// head inside by a hair (the last link's contact step), within twice the head's depth: along a
// chain lying on a surface, link after link, that depth would double each link. So a tail inside
// a collider by no more than rounding (1e-9 of its link) is put on the surface along its normal
// and back at its link's length from `head`, where that leaves the link no less clear.
void SettleTail(int dim, const Eigen::Vector3d& head, double length,
                const std::vector<Collider>& colliders, Eigen::Vector3d* tail);

}  // namespace flexkin::internal

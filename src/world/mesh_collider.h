#pragma once
// Closed triangle meshes as colliders (docs/colliders.md, "Meshes"): where a point and a segment
// stand with respect to the solid a mesh bounds. FCL's bounding volume hierarchy (OBBRSS, built
// once per mesh) prunes the triangles; the distances to the triangles left are computed here in
// closed form, and the side by the angle-weighted pseudo-normal of the nearest feature (a face,
// an edge or a vertex), which is exact for a closed, consistently oriented mesh (J. A. Baerentzen
// and H. Aanaes, "Signed distance computation using the angle weighted pseudonormal", IEEE TVCG
// 2005). Everything here is in the mesh's own frame, before the collider's scale.

#include <Eigen/Core>

#include "flexkin/colliders.h"

namespace flexkin::internal {

// The point `p` (the mesh's frame, unscaled) with respect to the mesh's surface: signed distance
// (negative inside), nearest point of the surface, outward normal.
SurfaceQuery MeshSurface(const ColliderMeshData& mesh, const Eigen::Vector3d& p);

// The least signed distance of the segment [a, b] (the mesh's frame, unscaled) to the solid: the
// distance between the segment and the surface where the segment is outside; negative where any
// part of it is inside, by at least the depth of its deepest point among the midpoints of its
// parts between crossings of the surface and its ends (the sign is exact, the depth a lower
// bound).
double MeshSegmentClearance(const ColliderMeshData& mesh, const Eigen::Vector3d& a,
                            const Eigen::Vector3d& b);

// Where the mesh's feature nearest p (its frame, unscaled) is a convex edge: its ends (`from` to
// `to`, in the order of the face on one side) and the outward normals of its two faces; false
// for a face, a vertex, or a flat or reflex edge.
bool MeshNearestConvexEdge(const ColliderMeshData& mesh, const Eigen::Vector3d& p,
                           Eigen::Vector3d* from, Eigen::Vector3d* to, Eigen::Vector3d* n1,
                           Eigen::Vector3d* n2);

// A lower bound of MeshSegmentClearance(mesh, a, b), cheap: the segment's distance to the box of
// the mesh's hierarchy that holds every triangle (less the hierarchy's padding); at most 0 where
// the segment meets that box (broad phases).
double MeshSegmentLowerBound(const ColliderMeshData& mesh, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b);

// Whether the least signed distance of [a, b] is below `threshold` (the mesh's frame, unscaled),
// for `a` outside the solid or on its surface (the contact step's head): the contact search's
// test, which needs no distance, only the crossings (threshold <= 0) or the first triangle
// nearer than the threshold (> 0).
bool MeshSegmentEnters(const ColliderMeshData& mesh, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double threshold);

}  // namespace flexkin::internal

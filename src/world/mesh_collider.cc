// Closed triangle meshes as colliders (world/mesh_collider.h, docs/colliders.md "Meshes").
#include "world/mesh_collider.h"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <utility>
#include <vector>

namespace flexkin {
namespace internal {

// The hierarchy (FCL's, over the triangles in their input order) and the pseudo-normals.
struct MeshBvh {
  fcl::BVHModel<fcl::OBBRSSd> model;
  std::vector<Eigen::Vector3d> face_normal;    // unit, outward (zero for a triangle of no area)
  std::vector<std::array<int, 3>> face_edges;  // edge k runs from corner k to corner k + 1
  std::vector<Eigen::Vector3d> edge_normal;    // the sum of its two faces' normals
  std::vector<Eigen::Vector3d> vertex_normal;  // the angle-weighted sum of its faces' normals
  double pad = 0.0;  // added to every bound: FCL fits the boxes to rounding
  uint64_t id = 0;   // unique per mesh built in this process (a cache's key; an address is not)
};

namespace {

using Eigen::Vector3d;

// A point of a triangle and which feature of it: -1 its face, 0..2 a corner, 3..5 the edge from
// corner k - 3 to the next.
struct OnTriangle {
  Vector3d point;
  int feature = -1;
};

// The point of the triangle (a, b, c) nearest p, by the Voronoi regions of its corners, edges
// and face, each told by the signs of dot products (the barycentric coordinates of p's
// projection, unnormalized).
OnTriangle NearestOnTriangle(const Vector3d& p, const Vector3d& a, const Vector3d& b,
                             const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, 0};
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return {a + (d1 / (d1 - d3)) * ab, 3};
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return {a + (d2 / (d2 - d6)) * ac, 5};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), 4};
  }
  const double scale = 1.0 / (va + vb + vc);
  return {a + (vb * scale) * ab + (vc * scale) * ac, -1};
}

// The closest points of the segments p + s (q - p) and r + t (u - r), s and t in [0, 1].
void ClosestOnSegments(const Vector3d& p, const Vector3d& q, const Vector3d& r, const Vector3d& u,
                       double* s, double* t) {
  const Vector3d d1 = q - p, d2 = u - r, w = p - r;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(w);
  *s = 0.0;
  *t = 0.0;
  if (a == 0.0 && e == 0.0) return;
  if (a == 0.0) {
    *t = std::clamp(f / e, 0.0, 1.0);
    return;
  }
  const double c = d1.dot(w);
  if (e == 0.0) {
    *s = std::clamp(-c / a, 0.0, 1.0);
    return;
  }
  const double b = d1.dot(d2), denom = a * e - b * b;
  *s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  *t = (b * *s + f) / e;
  if (*t < 0.0) {
    *t = 0.0;
    *s = std::clamp(-c / a, 0.0, 1.0);
  } else if (*t > 1.0) {
    *t = 1.0;
    *s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

// Where the segment [a, b] crosses the triangle's plane inside the triangle (its parameter), or
// -1. Inclusive by a relative 1e-10 of the barycentric coordinates, so that a segment through an
// edge is seen by both its triangles rather than by neither; a segment in the plane is not a
// crossing (it touches, which the distance says).
double CrossingOf(const Vector3d& a, const Vector3d& b, const Vector3d& v0, const Vector3d& v1,
                  const Vector3d& v2) {
  const Vector3d n = (v1 - v0).cross(v2 - v0);
  const double da = n.dot(a - v0), db = n.dot(b - v0);
  if ((da > 0.0 && db > 0.0) || (da < 0.0 && db < 0.0) || da == db) return -1.0;
  const double t = da / (da - db);
  const Vector3d x = a + t * (b - a);
  const double n2 = n.squaredNorm();
  if (!(n2 > 0.0)) return -1.0;
  const double w0 = (v1 - x).cross(v2 - x).dot(n) / n2, w1 = (v2 - x).cross(v0 - x).dot(n) / n2;
  const double w2 = 1.0 - w0 - w1;
  constexpr double kTol = -1e-10;
  return w0 >= kTol && w1 >= kTol && w2 >= kTol ? t : -1.0;
}

// Lower bounds of the distance from a point and a segment to a node's box (FCL's OBB; its
// columns are the box's axes).
double PointBoxDistance(const fcl::OBBd& box, const Vector3d& p) {
  const Vector3d q = box.axis.transpose() * (p - box.To);
  return (q.cwiseAbs() - box.extent).cwiseMax(0.0).norm();
}

double SegmentBoxBound(const fcl::OBBd& box, const Vector3d& a, const Vector3d& b) {
  const Vector3d qa = box.axis.transpose() * (a - box.To), qb = box.axis.transpose() * (b - box.To);
  double gap = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double lo = std::min(qa[k], qb[k]), hi = std::max(qa[k], qb[k]);
    gap = std::max({gap, lo - box.extent[k], -box.extent[k] - hi});
  }
  // The segment's distance to the box's centre, less the box's half diagonal.
  const Vector3d ab = qb - qa;
  const double ab2 = ab.squaredNorm();
  const double t = ab2 > 0.0 ? std::clamp(-qa.dot(ab) / ab2, 0.0, 1.0) : 0.0;
  return std::max(gap, (qa + t * ab).norm() - box.extent.norm());
}

// Whether the segment [a, b] meets the box (grown by pad): its parameter interval clipped by the
// three slabs is not empty.
bool SegmentMeetsBox(const fcl::OBBd& box, const Vector3d& a, const Vector3d& b, double pad) {
  const Vector3d qa = box.axis.transpose() * (a - box.To), qb = box.axis.transpose() * (b - box.To);
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double e = box.extent[k] + pad, d = qb[k] - qa[k];
    if (d == 0.0) {
      if (std::fabs(qa[k]) > e) return false;
      continue;
    }
    double t0 = (-e - qa[k]) / d, t1 = (e - qa[k]) / d;
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
    if (lo > hi) return false;
  }
  return true;
}

Vector3d Corner(const ColliderMeshData& m, int face, int k) {
  return m.vertices.row(m.triangles(face, k)).transpose();
}

// The pseudo-normal of a feature of a face.
const Vector3d& PseudoNormal(const ColliderMeshData& m, int face, int feature) {
  const MeshBvh& h = *m.bvh;
  if (feature < 0) return h.face_normal[face];
  if (feature < 3) return h.vertex_normal[m.triangles(face, feature)];
  return h.edge_normal[h.face_edges[face][feature - 3]];
}

// The nodes still to visit, each with a lower bound of its distance: on the stack for the usual
// depths (a depth-first walk holds at most the tree's depth plus one), on the heap beyond.
class NodeStack {
 public:
  bool empty() const { return size_ == 0; }
  void push(int id, double bound) {
    if (size_ < kFixed) {
      fixed_[size_] = {id, bound};
    } else {
      more_.resize(size_ - kFixed + 1);
      more_.back() = {id, bound};
    }
    ++size_;
  }
  std::pair<int, double> pop() {
    --size_;
    if (size_ < kFixed) return fixed_[size_];
    const auto top = more_.back();
    more_.pop_back();
    return top;
  }

 private:
  static constexpr size_t kFixed = 128;
  std::array<std::pair<int, double>, kFixed> fixed_;
  std::vector<std::pair<int, double>> more_;
  size_t size_ = 0;
};

// The nearest surface point to p: its distance, the point, its face and feature. Branch and
// bound over the hierarchy, the nearer child first.
struct Nearest {
  double distance = std::numeric_limits<double>::infinity();
  Vector3d point = Vector3d::Zero();
  int face = -1, feature = -1;
};

// The branch and bound both nearest searches share: nodes visited nearest-first by `box_bound`
// (a lower bound of the distance to anything in an oriented box), pruned where that bound, less
// the hierarchy's padding, is not below the best distance so far; `leaf(face, &best)` measures
// a triangle and returns true to end the search.
template <class BoxBound, class Leaf>
Nearest SearchNearest(const MeshBvh& h, double bound, const BoxBound& box_bound, const Leaf& leaf) {
  Nearest best;
  best.distance = bound;
  NodeStack stack;
  stack.push(0, box_bound(h.model.getBV(0).bv.obb));
  while (!stack.empty()) {
    const auto [id, lower] = stack.pop();
    if (lower - h.pad >= best.distance) continue;
    const auto& node = h.model.getBV(id);
    if (node.isLeaf()) {
      if (leaf(node.primitiveId(), &best)) return best;
      continue;
    }
    const int l = node.leftChild(), r = node.rightChild();
    const double dl = box_bound(h.model.getBV(l).bv.obb), dr = box_bound(h.model.getBV(r).bv.obb);
    if (dl <= dr) {
      stack.push(r, dr), stack.push(l, dl);
    } else {
      stack.push(l, dl), stack.push(r, dr);
    }
  }
  return best;
}

// Only triangles nearer than `bound` are looked at (none found: best.face stays -1).
Nearest NearestToPoint(const ColliderMeshData& m, const Vector3d& p,
                       double bound = std::numeric_limits<double>::infinity()) {
  return SearchNearest(
      *m.bvh, bound, [&](const fcl::OBBd& box) { return PointBoxDistance(box, p); },
      [&](int f, Nearest* best) {
        const OnTriangle on =
            NearestOnTriangle(p, Corner(m, f, 0), Corner(m, f, 1), Corner(m, f, 2));
        const double d = (p - on.point).norm();
        if (d < best->distance) *best = {d, on.point, f, on.feature};
        return false;
      });
}

// The same for the segment [a, b]: the closest pair (s: the segment's parameter). A triangle the
// segment crosses is at distance 0.
// With a `bound`, only triangles nearer than it are looked at, and the first found ends the
// search (`first`).
Nearest NearestToSegment(const ColliderMeshData& m, const Vector3d& a, const Vector3d& b, double* s,
                         double bound = std::numeric_limits<double>::infinity(),
                         bool first = false) {
  return SearchNearest(
      *m.bvh, bound, [&](const fcl::OBBd& box) { return SegmentBoxBound(box, a, b); },
      [&](int f, Nearest* best) {
        const Vector3d v[3] = {Corner(m, f, 0), Corner(m, f, 1), Corner(m, f, 2)};
        const auto consider = [&](double t, const OnTriangle& on) {
          const double d = (a + t * (b - a) - on.point).norm();
          if (d < best->distance) *best = {d, on.point, f, on.feature}, *s = t;
        };
        const double crossing = CrossingOf(a, b, v[0], v[1], v[2]);
        if (crossing >= 0.0) {
          const Vector3d x = a + crossing * (b - a);
          consider(crossing, NearestOnTriangle(x, v[0], v[1], v[2]));
          return first && best->face >= 0;
        }
        consider(0.0, NearestOnTriangle(a, v[0], v[1], v[2]));
        consider(1.0, NearestOnTriangle(b, v[0], v[1], v[2]));
        for (int k = 0; k < 3; ++k) {
          double t, u;
          ClosestOnSegments(a, b, v[k], v[(k + 1) % 3], &t, &u);
          const int feature = u <= 0.0 ? k : u >= 1.0 ? (k + 1) % 3 : 3 + k;
          consider(t, {v[k] + u * (v[(k + 1) % 3] - v[k]), feature});
        }
        return first && best->face >= 0;
      });
}

// The parameters at which [a, b] crosses a triangle, with the triangle, sorted.
std::vector<std::pair<double, int>> Crossings(const ColliderMeshData& m, const Vector3d& a,
                                              const Vector3d& b) {
  const MeshBvh& h = *m.bvh;
  std::vector<std::pair<double, int>> out;
  NodeStack stack;
  stack.push(0, 0.0);
  while (!stack.empty()) {
    const int id = stack.pop().first;
    const auto& node = h.model.getBV(id);
    if (!SegmentMeetsBox(node.bv.obb, a, b, h.pad)) continue;
    if (node.isLeaf()) {
      const int f = node.primitiveId();
      const double t = CrossingOf(a, b, Corner(m, f, 0), Corner(m, f, 1), Corner(m, f, 2));
      if (t >= 0.0) out.emplace_back(t, f);
      continue;
    }
    stack.push(node.leftChild(), 0.0);
    stack.push(node.rightChild(), 0.0);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Signed: negative where p is on the inner side of the nearest feature's pseudo-normal.
double Signed(const ColliderMeshData& m, const Vector3d& p, const Nearest& n) {
  return (p - n.point).dot(PseudoNormal(m, n.face, n.feature)) < 0.0 ? -n.distance : n.distance;
}

// Distances this small (relative to the mesh's size) are on the surface: the side of a point
// there is not told by its nearest feature but by the crossings around it.
double OnSurface(const ColliderMeshData& m) { return 1e-12 * m.radius; }

std::string Num(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

}  // namespace

SurfaceQuery MeshSurface(const ColliderMeshData& m, const Vector3d& p) {
  const Nearest n = NearestToPoint(m, p);
  SurfaceQuery q;
  q.nearest = n.point;
  q.distance = Signed(m, p, n);
  if (n.distance > OnSurface(m)) {
    q.normal = (p - n.point) / q.distance;  // outward: away from the point inside
  } else {
    q.normal = PseudoNormal(m, n.face, n.feature).normalized();
  }
  return q;
}

double MeshSegmentClearance(const ColliderMeshData& m, const Vector3d& a, const Vector3d& b) {
  double s = 0.0;
  const Nearest n = NearestToSegment(m, a, b, &s);
  if (n.distance > OnSurface(m)) {
    // The segment does not meet the surface: wholly outside or wholly inside.
    if (Signed(m, a + s * (b - a), n) >= 0.0) return n.distance;
    return -std::max({n.distance, -MeshSurface(m, a).distance, -MeshSurface(m, b).distance});
  }
  // It meets the surface: its parts between crossings are each outside or inside; the midpoint
  // of each tells which. The surface is no farther from it than the nearer crossing (or, with
  // none, than the segment's nearest point): a bound that spares the search of far triangles.
  std::vector<double> cuts = {0.0};
  for (const auto& [t, f] : Crossings(m, a, b)) cuts.push_back(t);
  cuts.push_back(1.0);
  const double ab = (b - a).norm();
  double least = n.distance;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    if (!(cuts[k + 1] - cuts[k] > 1e-12) && k != 0 && k + 2 != cuts.size()) continue;
    const double mid_t = 0.5 * (cuts[k] + cuts[k + 1]);
    const Vector3d mid = a + mid_t * (b - a);
    const double bound = cuts.size() > 2 ? 0.5 * (cuts[k + 1] - cuts[k]) * ab
                                         : n.distance + std::max(mid_t - s, s - mid_t) * ab;
    Nearest near = NearestToPoint(m, mid, bound * (1.0 + 1e-9) + 2.0 * m.bvh->pad);
    if (near.face < 0) near = NearestToPoint(m, mid);  // rounding: look everywhere
    const double signed_mid = Signed(m, mid, near);
    least = std::min(least, signed_mid);
    // A part inside that ends the segment may be deepest at that end (a link's end dipped into
    // a face).
    if (signed_mid < 0.0 && (k == 0 || k + 2 == cuts.size())) {
      least = std::min(least, MeshSurface(m, k == 0 ? a : b).distance);
    }
  }
  return least;
}

bool MeshNearestConvexEdge(const ColliderMeshData& m, const Vector3d& p, Vector3d* from,
                           Vector3d* to, Vector3d* n1, Vector3d* n2) {
  const Nearest n = NearestToPoint(m, p);
  if (n.face < 0 || n.feature < 3) return false;
  const int k = n.feature - 3;
  *from = Corner(m, n.face, k);
  *to = Corner(m, n.face, (k + 1) % 3);
  *n1 = m.bvh->face_normal[n.face];
  *n2 = m.bvh->edge_normal[m.bvh->face_edges[n.face][k]] - *n1;
  // The face runs counter-clockwise seen from outside: n1 x u points into it, and the other face
  // turns away from it at a convex edge.
  const Vector3d u = (*to - *from).normalized();
  return n2->dot(n1->cross(u)) < -1e-9;
}

double MeshSegmentLowerBound(const ColliderMeshData& m, const Vector3d& a, const Vector3d& b) {
  // Outside the root box by `gap`, every point of the segment is at least that far from every
  // triangle (each lies within the box, to the padding) and so outside the solid.
  return SegmentBoxBound(m.bvh->model.getBV(0).bv.obb, a, b) - m.bvh->pad;
}

namespace {

// The triangles within `radius` of a head `a`, with what the test of a segment from `a` needs:
// the planes through `a` and each edge (a ray from `a` meets the triangle where it is on the
// same side of all three, the side of the triangle's volume seen from `a`). The contact search
// tests thousands of segments from one head, none longer than the link: the triangles are
// gathered once per head and thread (a one-entry cache), not once per segment.
struct NearHead {
  uint64_t mesh = 0;  // MeshBvh::id
  Vector3d a = Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  double radius = -1.0;
  struct Triangle {
    int face;
    std::array<Vector3d, 3> edge_planes;
    double volume;    // (v0 - a) . ((v1 - a) x (v2 - a)); ~0: `a` in its plane, tested directly
    double plane;     // face_normal . (v0 - a)
    double span;      // |edge_planes[1]|: the scale of `volume`
    Vector3d normal;  // the face's (MeshBvh::face_normal), kept beside the rest for the loop
  };
  std::vector<Triangle> triangles;
};

const NearHead& TrianglesNear(const ColliderMeshData& m, const Vector3d& a, double radius) {
  thread_local NearHead near;
  if (near.mesh == m.bvh->id && near.a == a && near.radius >= radius) return near;
  near.mesh = m.bvh->id;
  near.a = a;
  near.radius = radius;
  near.triangles.clear();
  const MeshBvh& h = *m.bvh;
  NodeStack stack;
  stack.push(0, 0.0);
  while (!stack.empty()) {
    const int id = stack.pop().first;
    const auto& node = h.model.getBV(id);
    if (PointBoxDistance(node.bv.obb, a) - h.pad > radius) continue;
    if (!node.isLeaf()) {
      stack.push(node.leftChild(), 0.0);
      stack.push(node.rightChild(), 0.0);
      continue;
    }
    const int f = node.primitiveId();
    const Vector3d v[3] = {Corner(m, f, 0) - a, Corner(m, f, 1) - a, Corner(m, f, 2) - a};
    if ((NearestOnTriangle(Vector3d::Zero(), v[0], v[1], v[2]).point).norm() > radius) continue;
    NearHead::Triangle t;
    t.face = f;
    for (int k = 0; k < 3; ++k) t.edge_planes[k] = v[k].cross(v[(k + 1) % 3]);
    t.volume = v[0].dot(t.edge_planes[1]);
    t.plane = h.face_normal[f].dot(v[0]);
    t.span = t.edge_planes[1].norm();
    t.normal = h.face_normal[f];
    near.triangles.push_back(t);
  }
  return near;
}

}  // namespace

bool MeshSegmentEnters(const ColliderMeshData& m, const Vector3d& a, const Vector3d& b,
                       double threshold) {
  if (threshold <= 0.0) {
    // From `a` (outside), each crossing enters or leaves: by the side its triangle faces. The
    // parts entered are inside; one deeper than -threshold makes the segment enter. Crossings
    // that disagree at one place (a segment grazing an edge) are told by the midpoint's nearest
    // feature.
    const Vector3d ab = b - a;
    const double length = ab.norm();
    const NearHead& near = TrianglesNear(m, a, length * (1.0 + 1e-9) + 2.0 * m.bvh->pad);
    thread_local std::vector<std::pair<double, int>> crossings;  // kept: no allocation a test
    crossings.clear();
    for (const NearHead::Triangle& t : near.triangles) {
      const double along = t.normal.dot(ab);
      if (std::fabs(t.plane) <= 1e-12 * length) {
        // The head on the triangle's plane (a contact step put it on the surface, to rounding,
        // either side): the segment crosses it at the head, if the head is on the triangle and
        // the segment leaves the plane.
        if (along == 0.0) continue;
        const Vector3d n = t.normal;
        if (CrossingOf(a + n, a - n, Corner(m, t.face, 0), Corner(m, t.face, 1),
                       Corner(m, t.face, 2)) >= 0.0) {
          crossings.emplace_back(0.0, t.face);
        }
        continue;
      }
      if (!(std::fabs(t.volume) > 1e-9 * length * t.span)) {
        const double c =
            CrossingOf(a, b, Corner(m, t.face, 0), Corner(m, t.face, 1), Corner(m, t.face, 2));
        if (c >= 0.0) crossings.emplace_back(c, t.face);
        continue;
      }
      // The plane is crossed within the segment: t.plane / along in [0, 1]. Told without the
      // division (its latency held the loop): |t.plane| > 1e-12 length >= 1e-12 |along| above,
      // so the quotient does not underflow and is negative exactly where the signs differ; and
      // for positive doubles x / y rounds above 1 exactly where x > y (a quotient in
      // (1, 1 + 2^-53] rounds to 1, and x > y makes it at least 1 + ulp(y) / y > 1 + 2^-53).
      if (along == 0.0 || (t.plane > 0.0) != (along > 0.0) ||
          std::fabs(t.plane) > std::fabs(along)) {
        continue;
      }
      // Exact signs, no tolerance: the plane through `a` and an edge is the same (negated
      // exactly) for the edge's two triangles, so a segment through an edge is counted by one of
      // them at least, and through a triangle near an edge by that triangle only.
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) {
        inside = t.edge_planes[k].dot(ab) * (t.volume > 0.0 ? 1.0 : -1.0) >= 0.0;
      }
      if (inside) crossings.emplace_back(t.plane / along, t.face);
    }
    std::sort(crossings.begin(), crossings.end());
    const double depth = -threshold;
    for (size_t k = 0; k < crossings.size();) {
      size_t end = k;
      int entering = 0, leaving = 0;
      for (; end < crossings.size() && crossings[end].first - crossings[k].first <= 1e-12; ++end) {
        const double side = ab.dot(m.bvh->face_normal[crossings[end].second]);
        entering += side < 0.0;
        leaving += side > 0.0;
      }
      const double from = crossings[k].first;
      const double to = end < crossings.size() ? crossings[end].first : 1.0;
      k = end;
      if (leaving > 0 && entering == 0) continue;
      // A part too short to hold a point apart from its ends, unless it ends the segment (a
      // link's end dipped into a face by a hair).
      if (!(to - from > 1e-12) && end < crossings.size()) continue;
      const Vector3d mid = a + 0.5 * (from + to) * ab;
      if (entering > 0 && leaving == 0) {
        // Inside: deeper than `depth` at its midpoint, or at the segment's end if it ends
        // inside (a link whose end dips into a face is deepest there), unless a triangle (one
        // near the head) is that near.
        const auto deep = [&](const Vector3d& x) {
          const Vector3d from_head = x - a;
          for (const NearHead::Triangle& t : near.triangles) {
            if (std::fabs(t.normal.dot(from_head) - t.plane) > depth) continue;
            const Vector3d v0 = Corner(m, t.face, 0), v1 = Corner(m, t.face, 1),
                           v2 = Corner(m, t.face, 2);
            if ((NearestOnTriangle(x, v0, v1, v2).point - x).norm() <= depth) return false;
          }
          return true;
        };
        if (deep(mid) || (end == crossings.size() && deep(b))) return true;
        continue;
      }
      const Nearest n =
          NearestToPoint(m, mid, 0.5 * (to - from) * length * (1.0 + 1e-9) + 2.0 * m.bvh->pad);
      if (n.face >= 0 && Signed(m, mid, n) < threshold) return true;
    }
    return false;
  }
  // Within `threshold` of the surface: any triangle that near ends the search. None: the
  // segment does not meet the surface, and `a` is outside, so neither is any of it inside.
  double s = 0.0;
  return NearestToSegment(m, a, b, &s, threshold, /*first=*/true).face >= 0;
}

}  // namespace internal

std::shared_ptr<const ColliderMeshData> MakeColliderMesh(MeshVertices vertices,
                                                         MeshTriangles triangles,
                                                         const std::string& file,
                                                         const std::string& field,
                                                         std::vector<Problem>* problems) {
  using Eigen::Vector3d;
  using internal::Num;
  const size_t before = problems->size();
  const auto refuse = [&](const std::string& message) {
    problems->emplace_back(field, message, file.empty() ? "" : "\"" + file + "\"",
                           "a closed triangle mesh (every edge shared by exactly two triangles, "
                           "consistently oriented)");
  };
  const int nv = static_cast<int>(vertices.rows()), nf = static_cast<int>(triangles.rows());
  if (nv == 0 || nf == 0) {
    refuse("is an empty mesh (" + std::to_string(nv) + " vertices, " + std::to_string(nf) +
           " triangles)");
    return nullptr;
  }
  for (int i = 0; i < nv; ++i) {
    if (!vertices.row(i).allFinite()) {
      refuse("has vertex " + std::to_string(i) + " (" + Num(vertices(i, 0)) + ", " +
             Num(vertices(i, 1)) + ", " + Num(vertices(i, 2)) + ") that is not finite");
      return nullptr;
    }
  }
  for (int f = 0; f < nf; ++f) {
    const auto t = triangles.row(f);
    if (t.minCoeff() < 0 || t.maxCoeff() >= nv) {
      refuse("has triangle " + std::to_string(f) + " with a vertex index outside 0.." +
             std::to_string(nv - 1));
      return nullptr;
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      refuse("has triangle " + std::to_string(f) + " (" + std::to_string(t[0]) + ", " +
             std::to_string(t[1]) + ", " + std::to_string(t[2]) + ") with a repeated vertex");
      return nullptr;
    }
  }
  // Every undirected edge: its triangles and the way each runs it.
  std::map<std::pair<int, int>, std::vector<std::pair<int, bool>>> edges;
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int i = triangles(f, k), j = triangles(f, (k + 1) % 3);
      edges[{std::min(i, j), std::max(i, j)}].emplace_back(f, i < j);
    }
  }
  int boundary = 0, crowded = 0, same_way = 0;
  std::string boundary_example, crowded_example, same_way_example;
  const auto edge_text = [&](const std::pair<int, int>& e) {
    const Vector3d p = vertices.row(e.first), q = vertices.row(e.second);
    return "vertices " + std::to_string(e.first) + " (" + Num(p.x()) + ", " + Num(p.y()) + ", " +
           Num(p.z()) + ") and " + std::to_string(e.second) + " (" + Num(q.x()) + ", " +
           Num(q.y()) + ", " + Num(q.z()) + ")";
  };
  for (const auto& [e, uses] : edges) {
    if (uses.size() == 1) {
      if (boundary++ == 0) boundary_example = edge_text(e);
    } else if (uses.size() > 2) {
      if (crowded++ == 0) crowded_example = edge_text(e);
    } else if (uses[0].second == uses[1].second) {
      if (same_way++ == 0) {
        same_way_example = edge_text(e) + ", in triangles " + std::to_string(uses[0].first) +
                           " and " + std::to_string(uses[1].first);
      }
    }
  }
  if (boundary > 0) {
    refuse("is an open mesh: " + std::to_string(boundary) +
           " boundary edges (in one triangle only), e.g. between " + boundary_example);
  }
  if (crowded > 0) {
    refuse("is not a closed surface: " + std::to_string(crowded) +
           " edges shared by more than two triangles, e.g. between " + crowded_example);
  }
  if (boundary == 0 && crowded == 0 && same_way > 0) {
    refuse("is not consistently oriented: " + std::to_string(same_way) +
           " edges run the same way by both their triangles, e.g. between " + same_way_example);
  }
  if (problems->size() != before) return nullptr;
  double six_volume = 0.0;
  for (int f = 0; f < nf; ++f) {
    const Vector3d a = vertices.row(triangles(f, 0)), b = vertices.row(triangles(f, 1)),
                   c = vertices.row(triangles(f, 2));
    six_volume += a.dot(b.cross(c));
  }
  if (!(six_volume != 0.0)) {
    refuse("encloses no volume");
    return nullptr;
  }
  if (six_volume < 0.0) triangles.col(1).swap(triangles.col(2));  // inside out: turned

  auto data = std::make_shared<ColliderMeshData>();
  auto bvh = std::make_shared<internal::MeshBvh>();
  bvh->face_normal.resize(nf);
  bvh->face_edges.resize(nf);
  bvh->vertex_normal.assign(nv, Vector3d::Zero());
  std::map<std::pair<int, int>, int> edge_ids;
  std::vector<double> lengths;
  for (int f = 0; f < nf; ++f) {
    const Vector3d v[3] = {vertices.row(triangles(f, 0)), vertices.row(triangles(f, 1)),
                           vertices.row(triangles(f, 2))};
    const Vector3d n = (v[1] - v[0]).cross(v[2] - v[0]);
    bvh->face_normal[f] = n.norm() > 0.0 ? Vector3d(n.normalized()) : Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const int i = triangles(f, k), j = triangles(f, (k + 1) % 3);
      const auto key = std::make_pair(std::min(i, j), std::max(i, j));
      auto [it, added] = edge_ids.emplace(key, static_cast<int>(bvh->edge_normal.size()));
      if (added) {
        bvh->edge_normal.push_back(Vector3d::Zero());
        lengths.push_back((v[(k + 1) % 3] - v[k]).norm());
      }
      bvh->face_edges[f][k] = it->second;
      bvh->edge_normal[it->second] += bvh->face_normal[f];
      // The corner's angle weights the face's normal at the vertex.
      const Vector3d e1 = v[(k + 1) % 3] - v[k], e2 = v[(k + 2) % 3] - v[k];
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      bvh->vertex_normal[i] += angle * bvh->face_normal[f];
    }
  }
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  data->feature = lengths[lengths.size() / 2];
  data->radius = vertices.rowwise().norm().maxCoeff();
  bvh->pad = 1e-12 * data->radius;
  static std::atomic<uint64_t> built{0};
  bvh->id = ++built;
  std::vector<fcl::Vector3d> points(nv);
  for (int i = 0; i < nv; ++i) points[i] = vertices.row(i).transpose();
  std::vector<fcl::Triangle> faces(nf);
  for (int f = 0; f < nf; ++f) faces[f].set(triangles(f, 0), triangles(f, 1), triangles(f, 2));
  bvh->model.beginModel(nf, nv);
  bvh->model.addSubModel(points, faces);
  bvh->model.endModel();
  data->file = file;
  data->vertices = std::move(vertices);
  data->triangles = std::move(triangles);
  data->bvh = std::move(bvh);
  return data;
}

}  // namespace flexkin

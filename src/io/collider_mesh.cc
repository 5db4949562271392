// The colliders' geometry for pictures and scenes (io/collider_mesh.h): surfaces of revolution
// turned from a profile, the box's faces, sections by z = 0 and planes clipped to boxes.
#include "io/collider_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "flexkin/result_io.h"
#include "flexkin/strand_file.h"

namespace flexkin {
namespace {

// A profile point of a surface of revolution about the local z axis: distance from the axis and
// height (rho = 0: a pole, one vertex).
struct ProfilePoint {
  double rho, z;
};

// Turns `profile` (from the top down) about z with `segments` meridians, in local coordinates.
ColliderMesh Lathe(const std::vector<ProfilePoint>& profile, int segments) {
  ColliderMesh mesh;
  std::vector<int> first;  // first vertex of each profile point's ring
  for (const ProfilePoint& p : profile) {
    first.push_back(static_cast<int>(mesh.vertices.size()));
    if (p.rho == 0.0) {
      mesh.vertices.emplace_back(0.0, 0.0, p.z);
      continue;
    }
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * M_PI * j / segments;
      mesh.vertices.emplace_back(p.rho * std::cos(phi), p.rho * std::sin(phi), p.z);
    }
  }
  for (size_t r = 0; r + 1 < profile.size(); ++r) {
    const bool top_pole = profile[r].rho == 0.0, bottom_pole = profile[r + 1].rho == 0.0;
    if (top_pole && bottom_pole) continue;
    for (int j = 0; j < segments; ++j) {
      const int k = (j + 1) % segments;
      const int u0 = first[r] + (top_pole ? 0 : j), u1 = first[r] + (top_pole ? 0 : k);
      const int l0 = first[r + 1] + (bottom_pole ? 0 : j);
      const int l1 = first[r + 1] + (bottom_pole ? 0 : k);
      if (!bottom_pole) mesh.triangles.push_back({u0, l0, l1});
      if (!top_pole) mesh.triangles.push_back({u0, l1, u1});
    }
  }
  return mesh;
}

// A sphere's profile (radius `r`), `rings` latitudes from pole to pole; the upper half raised by
// `lift` and the lower lowered by it (a capsule: its equator becomes the cylinder between).
std::vector<ProfilePoint> RoundProfile(double r, int rings, double lift) {
  std::vector<ProfilePoint> profile;
  const int half = std::max(2, rings / 2);
  for (int i = 0; i <= half; ++i) {  // north pole to equator
    const double theta = 0.5 * M_PI * i / half;
    profile.push_back({i == 0 ? 0.0 : r * std::sin(theta), r * std::cos(theta) + lift});
  }
  for (int i = lift > 0.0 ? 0 : 1; i <= half; ++i) {  // equator (again, if lifted) to south pole
    const double theta = 0.5 * M_PI + 0.5 * M_PI * i / half;
    profile.push_back({i == half ? 0.0 : r * std::sin(theta), r * std::cos(theta) - lift});
  }
  return profile;
}

ColliderMesh BoxMesh(const Eigen::Vector3d& e) {
  ColliderMesh mesh;
  for (int c = 0; c < 8; ++c) {
    mesh.vertices.emplace_back(c & 1 ? e.x() : -e.x(), c & 2 ? e.y() : -e.y(),
                               c & 4 ? e.z() : -e.z());
  }
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, d = (a + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      int quad[4];
      const int corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int q = 0; q < 4; ++q) {
        quad[q] = (side << a) | (corners[q][0] << b) | (corners[q][1] << d);
      }
      mesh.triangles.push_back({quad[0], quad[1], quad[2]});
      mesh.triangles.push_back({quad[0], quad[2], quad[3]});
    }
  }
  return mesh;
}

// Turns every triangle of a convex mesh about its local origin (inside it) to face outward.
void FaceOutward(ColliderMesh* mesh) {
  for (std::array<int, 3>& t : mesh->triangles) {
    const Eigen::Vector3d& a = mesh->vertices[t[0]];
    const Eigen::Vector3d& b = mesh->vertices[t[1]];
    const Eigen::Vector3d& c = mesh->vertices[t[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0.0) std::swap(t[1], t[2]);
  }
}

// Clips a convex polygon to the side n . x <= d of a plane (Sutherland-Hodgman).
std::vector<Eigen::Vector3d> Clip(const std::vector<Eigen::Vector3d>& polygon,
                                  const Eigen::Vector3d& n, double d) {
  std::vector<Eigen::Vector3d> out;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
    const double da = n.dot(a) - d, db = n.dot(b) - d;
    if (da <= 0.0) out.push_back(a);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      out.push_back(a + (da / (da - db)) * (b - a));
    }
  }
  return out;
}

std::vector<Eigen::Vector3d> ClipToBox(std::vector<Eigen::Vector3d> polygon,
                                       const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                       int axes) {
  for (int a = 0; a < axes && !polygon.empty(); ++a) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(a);
    polygon = Clip(polygon, e, hi[a]);
    if (!polygon.empty()) polygon = Clip(polygon, -e, -lo[a]);
  }
  return polygon;
}

}  // namespace

ColliderMesh MeshOfCollider(const Collider& c, int segments, const Eigen::Vector3d& center,
                            double half_size) {
  ColliderMesh mesh;
  switch (c.shape) {
    case ColliderShape::kSphere:
      mesh = Lathe(RoundProfile(c.radius, segments / 2, 0.0), segments);
      break;
    case ColliderShape::kEllipsoid:
      mesh = Lathe(RoundProfile(1.0, segments / 2, 0.0), segments);
      for (Eigen::Vector3d& v : mesh.vertices) v = v.cwiseProduct(c.extents);
      break;
    case ColliderShape::kCapsule:
      mesh = Lathe(RoundProfile(c.radius, segments / 2, c.half_length), segments);
      break;
    case ColliderShape::kCylinder:
      mesh = Lathe({{0.0, c.half_length},
                    {c.radius, c.half_length},
                    {c.radius, -c.half_length},
                    {0.0, -c.half_length}},
                   segments);
      break;
    case ColliderShape::kBox:
      mesh = BoxMesh(c.extents);
      break;
    case ColliderShape::kHalfSpace: {
      const Eigen::Vector3d foot = c.pose.inverse() * center;
      const double s = half_size;
      for (const auto& [x, y] : {std::pair{-s, -s}, {s, -s}, {s, s}, {-s, s}}) {
        mesh.vertices.push_back(c.pose * Eigen::Vector3d(foot.x() + x, foot.y() + y, 0.0));
      }
      mesh.triangles = {{0, 1, 2}, {0, 2, 3}};  // counter-clockwise seen from +z, the free side
      return mesh;
    }
    case ColliderShape::kMesh: {  // its own triangles, outward already (MakeColliderMesh)
      const ColliderMeshData& m = *c.mesh;
      for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
        mesh.vertices.push_back(c.pose * (c.scale * m.vertices.row(i).transpose()).eval());
      }
      for (Eigen::Index f = 0; f < m.triangles.rows(); ++f) {
        mesh.triangles.push_back({m.triangles(f, 0), m.triangles(f, 1), m.triangles(f, 2)});
      }
      return mesh;
    }
  }
  FaceOutward(&mesh);
  for (Eigen::Vector3d& v : mesh.vertices) v = c.pose * v;
  return mesh;
}

std::vector<Eigen::Vector2d> OutlineOfCollider2d(const Collider& c, int segments,
                                                 const Eigen::Vector2d& lo,
                                                 const Eigen::Vector2d& hi) {
  const Eigen::Vector2d t = c.pose.translation().head<2>();
  const Eigen::Matrix2d r = c.pose.linear().topLeftCorner<2, 2>();
  std::vector<Eigen::Vector2d> outline;
  // An arc of radius `radius` about `o` from angle a0 to a1 (counter-clockwise).
  const auto arc = [&](const Eigen::Vector2d& o, double radius, double a0, double a1, int n) {
    for (int i = 0; i <= n; ++i) {
      const double a = a0 + (a1 - a0) * i / n;
      outline.push_back(o + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
  };
  switch (c.shape) {
    case ColliderShape::kSphere: {
      const double z = c.pose.translation().z(), rho2 = c.radius * c.radius - z * z;
      if (rho2 > 0.0)
        arc(t, std::sqrt(rho2), 0.0, 2.0 * M_PI * (segments - 1) / segments, segments - 1);
      break;
    }
    case ColliderShape::kCapsule: {
      const Eigen::Vector2d axis = c.pose.linear().col(2).head<2>();
      if (c.half_length == 0.0 || axis.norm() == 0.0) {
        arc(t, c.radius, 0.0, 2.0 * M_PI * (segments - 1) / segments, segments - 1);
        break;
      }
      const double along = std::atan2(axis.y(), axis.x());
      const Eigen::Vector2d a = axis.normalized() * c.half_length;
      arc(t + a, c.radius, along - 0.5 * M_PI, along + 0.5 * M_PI, segments / 2);
      arc(t - a, c.radius, along + 0.5 * M_PI, along + 1.5 * M_PI, segments / 2);
      break;
    }
    case ColliderShape::kCylinder: {
      const Eigen::Vector2d a = c.pose.linear().col(2).head<2>().normalized();
      const Eigen::Vector2d h = c.half_length * a, w = c.radius * Eigen::Vector2d(-a.y(), a.x());
      outline = {t - h - w, t + h - w, t + h + w, t - h + w};
      break;
    }
    case ColliderShape::kBox: {
      const Eigen::Vector2d e = c.extents.head<2>();
      for (const auto& [x, y] : {std::pair{-1.0, -1.0}, {1.0, -1.0}, {1.0, 1.0}, {-1.0, 1.0}}) {
        outline.push_back(t + r * Eigen::Vector2d(x * e.x(), y * e.y()));
      }
      break;
    }
    case ColliderShape::kEllipsoid:
      for (int i = 0; i < segments; ++i) {
        const double a = 2.0 * M_PI * i / segments;
        outline.push_back(
            t + r * Eigen::Vector2d(c.extents.x() * std::cos(a), c.extents.y() * std::sin(a)));
      }
      break;
    case ColliderShape::kHalfSpace: {
      const Eigen::Vector3d n(c.pose.linear()(0, 2), c.pose.linear()(1, 2), 0.0);
      std::vector<Eigen::Vector3d> box = {{lo.x(), lo.y(), 0.0},
                                          {hi.x(), lo.y(), 0.0},
                                          {hi.x(), hi.y(), 0.0},
                                          {lo.x(), hi.y(), 0.0}};
      for (const Eigen::Vector3d& p : Clip(box, n, n.dot(c.pose.translation()))) {
        outline.push_back(p.head<2>());
      }
      break;
    }
    case ColliderShape::kMesh:  // 3D only: refused in 2D (CollidersProblems)
      break;
  }
  return outline;
}

std::vector<Eigen::Vector3d> HalfSpacePlaneInBox(const Collider& c, const Eigen::Vector3d& lo,
                                                 const Eigen::Vector3d& hi) {
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  const double size = std::max((hi - lo).norm(), 1e-12);
  const ColliderMesh quad = MeshOfCollider(c, 8, mid, 2.0 * size);
  return ClipToBox(quad.vertices, lo, hi, 3);
}

void ExtendByCollider(const Collider& c, int dim, const Eigen::Vector3d& center,
                      Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  const Eigen::Matrix3d r = c.pose.linear();
  const Eigen::Vector3d t = c.pose.translation();
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  Eigen::Vector3d mid = t;
  switch (c.shape) {
    case ColliderShape::kSphere:
      half.setConstant(c.radius);
      break;
    case ColliderShape::kCapsule:
      half = c.half_length * r.col(2).cwiseAbs() + Eigen::Vector3d::Constant(c.radius);
      break;
    case ColliderShape::kCylinder:
      for (int k = 0; k < 3; ++k) {
        const double a = r(k, 2);
        half[k] = c.half_length * std::abs(a) + c.radius * std::sqrt(std::max(0.0, 1.0 - a * a));
      }
      break;
    case ColliderShape::kBox:
      half = r.cwiseAbs() * c.extents;
      break;
    case ColliderShape::kEllipsoid:
      half = (r * c.extents.asDiagonal()).rowwise().norm();
      break;
    case ColliderShape::kHalfSpace: {
      // Its boundary's point nearest `center`, and a band of the solid under it, 15% of what
      // the box holds so far deep, so that the shaded side shows.
      const Eigen::Vector3d foot = QuerySurface(c, center).nearest;
      const double extent = (*hi - *lo).head(dim == 2 ? 2 : 3).maxCoeff();
      const Eigen::Vector3d under = foot - (std::isfinite(extent) ? 0.15 * extent : 0.0) * r.col(2);
      mid = 0.5 * (foot + under);
      half = 0.5 * (foot - under).cwiseAbs();
      break;
    }
    case ColliderShape::kMesh: {  // the box of its vertices, placed
      Eigen::Vector3d a = Eigen::Vector3d::Constant(HUGE_VAL), b = -a;
      for (Eigen::Index i = 0; i < c.mesh->vertices.rows(); ++i) {
        const Eigen::Vector3d v = c.pose * (c.scale * c.mesh->vertices.row(i).transpose()).eval();
        a = a.cwiseMin(v);
        b = b.cwiseMax(v);
      }
      mid = 0.5 * (a + b);
      half = 0.5 * (b - a);
      break;
    }
  }
  const int axes = dim == 2 ? 2 : 3;
  for (int k = 0; k < axes; ++k) {
    (*lo)[k] = std::min((*lo)[k], mid[k] - half[k]);
    (*hi)[k] = std::max((*hi)[k], mid[k] + half[k]);
  }
}

void BoundsOfMotion(const ResultFile& file, Eigen::Vector3d* lo, Eigen::Vector3d* hi) {
  *lo = Eigen::Vector3d::Constant(HUGE_VAL);
  *hi = -*lo;
  for (const Frame& frame : file.result.frames) {
    for (Eigen::Index i = 0; i < frame.points.rows(); ++i) {
      Eigen::Vector3d q = Eigen::Vector3d::Zero();
      q.head(file.dim) = frame.points.row(i).transpose();
      *lo = lo->cwiseMin(q);
      *hi = hi->cwiseMax(q);
    }
  }
}

std::vector<Collider> BodyCollidersBesideScalp(const StrandFileHeader& header) {
  const ScalpShape& scalp = header.scalp;
  const auto is_scalp = [&](const Collider& c) {
    if (c.pose.translation() != scalp.center || !c.pose.linear().isIdentity(0.0)) return false;
    if (scalp.shape == "sphere") {
      return c.shape == ColliderShape::kSphere && c.radius == scalp.radii[0];
    }
    return scalp.shape == "ellipsoid" && c.shape == ColliderShape::kEllipsoid &&
           c.extents == scalp.radii;
  };
  std::vector<Collider> colliders;
  for (const Collider& c : header.body_colliders) {
    if (!is_scalp(c)) colliders.push_back(c);
  }
  return colliders;
}

void ExtendByColliderOverFrames(const Collider& collider, const ResultFile& file, int dim,
                                const Eigen::Vector3d& center, Eigen::Vector3d* lo,
                                Eigen::Vector3d* hi) {
  if (!collider.motion) return ExtendByCollider(collider, dim, center, lo, hi);
  const Frames& frames = file.result.frames;
  const size_t count = frames.size();
  const size_t every = std::max<size_t>(1, (count + 255) / 256);
  for (size_t f = 0; f < count; f += every) {
    ExtendByCollider(ColliderAt(collider, double(frames[f].step)), dim, center, lo, hi);
  }
  if (count > 0) {
    ExtendByCollider(ColliderAt(collider, double(frames[count - 1].step)), dim, center, lo, hi);
  }
}

Eigen::Isometry3d MotionPoseAt(const Collider& collider, double time) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (!collider.motion) return m;
  const BodyPose p =
      InterpolateKeyframes(collider.motion->keyframes, collider.motion->interpolation, time);
  m.linear() = p.rotation;
  m.translation() = p.translation;
  return m;
}

std::vector<Eigen::Isometry3d> MovesFromFirstFrame(const Collider& collider,
                                                   const ResultFile& file) {
  const Frames& frames = file.result.frames;
  std::vector<Eigen::Isometry3d> moves;
  if (frames.size() == 0) return moves;
  const Eigen::Isometry3d to_first = MotionPoseAt(collider, double(frames[0].step)).inverse();
  moves.reserve(frames.size());
  for (const Frame& frame : frames) {
    moves.push_back(MotionPoseAt(collider, double(frame.step)) * to_first);
  }
  return moves;
}

}  // namespace flexkin

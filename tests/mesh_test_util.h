#pragma once
// Triangle meshes the collider tests build (a union of cells, a surface of revolution, a capsule)
// and the tests' own brute force over every triangle of a placed mesh: point and segment
// distances, and the side by the generalized winding number (not the pseudo-normals the library
// uses).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "flexkin/colliders.h"

namespace flexkin::mesh_test {

using Eigen::Vector3d;

struct TestMesh {
  MeshVertices vertices;
  MeshTriangles triangles;
};

inline TestMesh FromLists(const std::vector<Vector3d>& v,
                          const std::vector<std::array<int, 3>>& t) {
  TestMesh m;
  m.vertices.resize(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) m.vertices.row(i) = v[i].transpose();
  m.triangles.resize(t.size(), 3);
  for (size_t f = 0; f < t.size(); ++f) {
    for (int k = 0; k < 3; ++k) m.triangles(f, k) = t[f][k];
  }
  return m;
}

// The surface of a union of unit cells (i, j, k) scaled by `h` and shifted by `origin`: every
// cell face not shared by two cells, as two triangles counter-clockwise seen from outside.
inline TestMesh Voxels(const std::vector<std::array<int, 3>>& cells, double h,
                       const Vector3d& origin) {
  std::map<std::array<int, 3>, int> filled, index;
  for (const auto& c : cells) filled[c] = 1;
  std::vector<Vector3d> v;
  std::vector<std::array<int, 3>> t;
  const auto vertex = [&](std::array<int, 3> p) {
    auto [it, added] = index.emplace(p, static_cast<int>(v.size()));
    if (added) v.push_back(origin + h * Vector3d(p[0], p[1], p[2]));
    return it->second;
  };
  for (const auto& c : cells) {
    for (int a = 0; a < 3; ++a) {
      for (int s : {-1, 1}) {
        std::array<int, 3> n = c;
        n[a] += s;
        if (filled.count(n)) continue;
        const int u = (a + 1) % 3, w = (a + 2) % 3;
        std::array<int, 3> p0 = c;
        if (s > 0) p0[a] += 1;
        std::array<int, 3> p1 = p0, p2 = p0, p3 = p0;
        p1[u] += 1;
        p2[u] += 1;
        p2[w] += 1;
        p3[w] += 1;
        const int q[4] = {vertex(p0), vertex(p1), vertex(p2), vertex(p3)};
        if (s > 0) {
          t.push_back({q[0], q[1], q[2]});
          t.push_back({q[0], q[2], q[3]});
        } else {
          t.push_back({q[0], q[2], q[1]});
          t.push_back({q[0], q[3], q[2]});
        }
      }
    }
  }
  return FromLists(v, t);
}

// A surface of revolution about z through the profile (rho, z) from the top pole to the bottom
// pole (rho 0 at both), `around` segments round.
inline TestMesh Lathe(const std::vector<std::pair<double, double>>& profile, int around) {
  std::vector<Vector3d> v = {Vector3d(0, 0, profile.front().second),
                             Vector3d(0, 0, profile.back().second)};
  const int rings = static_cast<int>(profile.size()) - 2;
  for (int r = 1; r <= rings; ++r) {
    for (int j = 0; j < around; ++j) {
      const double a = 2.0 * M_PI * j / around;
      v.emplace_back(profile[r].first * std::cos(a), profile[r].first * std::sin(a),
                     profile[r].second);
    }
  }
  const auto at = [&](int r, int j) { return 2 + (r - 1) * around + (j % around); };
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j < around; ++j) {
    t.push_back({0, at(1, j), at(1, j + 1)});
    for (int r = 1; r < rings; ++r) {
      t.push_back({at(r, j), at(r + 1, j), at(r + 1, j + 1)});
      t.push_back({at(r, j), at(r + 1, j + 1), at(r, j + 1)});
    }
    t.push_back({1, at(rings, j + 1), at(rings, j)});
  }
  return FromLists(v, t);
}

// A capsule of radius r about the z axis from -h to h, `around` segments round and `half` rings
// per hemisphere.
inline TestMesh CapsuleMesh(double r, double h, int around, int half) {
  std::vector<std::pair<double, double>> profile;
  for (int i = 0; i <= half; ++i) {
    const double a = 0.5 * M_PI * i / half;
    profile.emplace_back(r * std::sin(a), h + r * std::cos(a));
  }
  for (int i = half; i >= 0; --i) {
    const double a = 0.5 * M_PI * i / half;
    profile.emplace_back(r * std::sin(a), -h - r * std::cos(a));
  }
  return Lathe(profile, around);
}

inline Collider MeshCollider(const TestMesh& m,
                             const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity(),
                             double scale = 1.0) {
  std::vector<Problem> problems;
  Collider c;
  c.shape = ColliderShape::kMesh;
  c.mesh = MakeColliderMesh(m.vertices, m.triangles, "", "mesh", &problems);
  EXPECT_TRUE(problems.empty()) << problems.front().Text();
  c.pose = pose;
  c.scale = scale;
  return c;
}

// A box of half-extents `half` placed by `pose`, as a mesh of 12 triangles (one cell, centred and
// scaled per axis).
inline Collider BoxMesh(const Vector3d& half,
                        const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  TestMesh cube = Voxels({{0, 0, 0}}, 1.0, Vector3d::Constant(-0.5));
  EXPECT_EQ(cube.triangles.rows(), 12);
  for (Eigen::Index i = 0; i < cube.vertices.rows(); ++i) {
    cube.vertices.row(i) = (2.0 * cube.vertices.row(i).transpose()).cwiseProduct(half);
  }
  return MeshCollider(cube, pose);
}

// ---- The test's own brute force, over every triangle of the placed mesh. ----

struct World {
  std::vector<std::array<Vector3d, 3>> triangles;
};

inline World Placed(const Collider& c) {
  World w;
  const ColliderMeshData& m = *c.mesh;
  for (Eigen::Index f = 0; f < m.triangles.rows(); ++f) {
    std::array<Vector3d, 3> t;
    for (int k = 0; k < 3; ++k) {
      t[k] = c.pose * (c.scale * m.vertices.row(m.triangles(f, k)).transpose()).eval();
    }
    w.triangles.push_back(t);
  }
  return w;
}

inline double PointSegment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

// The distance from p to a triangle: to its plane where p projects inside it (the three edge
// tests), else to the nearest of its edges.
inline double PointTriangle(const Vector3d& p, const std::array<Vector3d, 3>& t) {
  const Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  const Vector3d q = p - (p - t[0]).dot(n) * n;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    if ((t[(k + 1) % 3] - t[k]).cross(q - t[k]).dot(n) < 0.0) inside = false;
  }
  if (inside) return std::fabs((p - t[0]).dot(n));
  double d = HUGE_VAL;
  for (int k = 0; k < 3; ++k) d = std::min(d, PointSegment(p, t[k], t[(k + 1) % 3]));
  return d;
}

// The generalized winding number: the solid angles of the triangles seen from p over 4 pi
// (A. van Oosterom and J. Strackee's formula); about 1 inside, 0 outside.
inline double Winding(const World& w, const Vector3d& p) {
  double sum = 0.0;
  for (const auto& t : w.triangles) {
    const Vector3d a = t[0] - p, b = t[1] - p, c = t[2] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2.0 * std::atan2(a.dot(b.cross(c)),
                            la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la);
  }
  return sum / (4.0 * M_PI);
}

inline double BruteSigned(const World& w, const Vector3d& p) {
  double d = HUGE_VAL;
  for (const auto& t : w.triangles) d = std::min(d, PointTriangle(p, t));
  return Winding(w, p) > 0.5 ? -d : d;
}

// The distance between a segment and the surface, by minimizing along the segment: the distance
// is sampled densely, then the best sample refined by golden-section search (the distance to one
// triangle is convex along the segment; the minimum over triangles is taken per point).
inline double BruteSegmentDistance(const World& w, const Vector3d& a, const Vector3d& b) {
  const auto f = [&](double s) {
    double d = HUGE_VAL;
    for (const auto& t : w.triangles) d = std::min(d, PointTriangle(a + s * (b - a), t));
    return d;
  };
  constexpr int kSamples = 400;
  int best = 0;
  double best_value = HUGE_VAL;
  for (int i = 0; i <= kSamples; ++i) {
    const double value = f(static_cast<double>(i) / kSamples);
    if (value < best_value) best_value = value, best = i;
  }
  double lo = std::max(0.0, (best - 1.0) / kSamples), hi = std::min(1.0, (best + 1.0) / kSamples);
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
    (f(m1) < f(m2) ? hi : lo) = f(m1) < f(m2) ? m2 : m1;
  }
  return std::min(best_value, f(0.5 * (lo + hi)));
}

}  // namespace flexkin::mesh_test

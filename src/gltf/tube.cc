#include "gltf/tube.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace flexkin::gltf {
namespace {

using Eigen::Vector3d;

class Builder {
 public:
  Builder(TubeMesh* mesh, const Eigen::Matrix3d& to_scene) : mesh_(mesh), to_scene_(to_scene) {
    // The rotation part of to_scene (a rotation times a positive scale) for the normals.
    rotation_ = to_scene / to_scene.col(0).norm();
  }

  // Adds a vertex at `position` (skeleton space) with `normal`, skinned to joints a and b with
  // weights 1 - wb and wb; returns its index.
  uint32_t Add(const Vector3d& position, const Vector3d& normal, int a, int b, float wb) {
    const Vector3d p = to_scene_ * position;
    const Vector3d n = (rotation_ * normal).normalized();
    for (int k = 0; k < 3; ++k) {
      mesh_->positions.push_back(static_cast<float>(p[k]));
      mesh_->normals.push_back(static_cast<float>(n[k]));
    }
    // Unused slots: joint 0 with weight 0 (the convention the glTF validator expects).
    const bool two = wb > 0.0f;
    mesh_->joints.insert(mesh_->joints.end(),
                         {static_cast<uint16_t>(a), static_cast<uint16_t>(two ? b : 0), 0, 0});
    mesh_->weights.insert(mesh_->weights.end(), {two ? 1.0f - wb : 1.0f, two ? wb : 0.0f, 0, 0});
    return static_cast<uint32_t>(mesh_->num_vertices() - 1);
  }

  void Triangle(uint32_t a, uint32_t b, uint32_t c) {
    mesh_->indices.insert(mesh_->indices.end(), {a, b, c});
  }

 private:
  TubeMesh* mesh_;
  Eigen::Matrix3d to_scene_;
  Eigen::Matrix3d rotation_;
};

// `sides` unit radial directions about +Y, evenly spaced.
std::vector<Vector3d> Around(int sides) {
  std::vector<Vector3d> around(sides);
  for (int k = 0; k < sides; ++k) {
    const double angle = 2.0 * M_PI * k / sides;
    around[k] = Vector3d(std::cos(angle), 0.0, std::sin(angle));
  }
  return around;
}

}  // namespace

TubeMesh MakeTube(const Eigen::VectorXd& arc, double radius, int sides,
                  const Eigen::Matrix3d& to_scene) {
  assert(arc.size() >= 2 && sides >= 3 && radius > 0.0);
  const int joints = static_cast<int>(arc.size());
  const int last = joints - 1;
  TubeMesh mesh;
  Builder builder(&mesh, to_scene);
  const std::vector<Vector3d> around = Around(sides);

  // The side: rings[j * sides + k].
  std::vector<uint32_t> ring(static_cast<size_t>(joints) * sides);
  for (int j = 0; j < joints; ++j) {
    // Inner rings: half to the bone ending here (joint j-1), half to the one starting here.
    const int a = j == 0 ? 0 : (j == last ? last : j - 1);
    const float wb = (j == 0 || j == last) ? 0.0f : 0.5f;
    for (int k = 0; k < sides; ++k) {
      const Vector3d position = Vector3d(0.0, arc[j], 0.0) + radius * around[k];
      ring[static_cast<size_t>(j) * sides + k] = builder.Add(position, around[k], a, j, wb);
    }
  }
  for (int j = 0; j < last; ++j) {
    for (int k = 0; k < sides; ++k) {
      const int k1 = (k + 1) % sides;
      const uint32_t a = ring[static_cast<size_t>(j) * sides + k];
      const uint32_t b = ring[static_cast<size_t>(j) * sides + k1];
      const uint32_t c = ring[static_cast<size_t>(j + 1) * sides + k];
      const uint32_t d = ring[static_cast<size_t>(j + 1) * sides + k1];
      builder.Triangle(a, c, b);
      builder.Triangle(b, c, d);
    }
  }

  // The caps: their own vertices, so that their normals are the tube's axis.
  for (const int j : {0, last}) {
    const double sign = j == 0 ? -1.0 : 1.0;
    const Vector3d normal(0.0, sign, 0.0);
    const uint32_t center = builder.Add(Vector3d(0.0, arc[j], 0.0), normal, j, j, 0.0f);
    std::vector<uint32_t> cap(sides);
    for (int k = 0; k < sides; ++k) {
      cap[k] = builder.Add(Vector3d(0.0, arc[j], 0.0) + radius * around[k], normal, j, j, 0.0f);
    }
    for (int k = 0; k < sides; ++k) {
      const uint32_t a = cap[k];
      const uint32_t b = cap[(k + 1) % sides];
      if (j == 0) {
        builder.Triangle(center, a, b);
      } else {
        builder.Triangle(center, b, a);
      }
    }
  }
  return mesh;
}

namespace {

// Joins two rings of the same number of vertices, `lower` before `upper` along the profile from
// the pole at joint 0 to the pole at the last joint, by two triangles per side, counter-clockwise
// seen from outside.
void JoinRings(const std::vector<uint32_t>& lower, const std::vector<uint32_t>& upper,
               Builder* builder) {
  const size_t sides = lower.size();
  for (size_t k = 0; k < sides; ++k) {
    const size_t k1 = (k + 1) % sides;
    builder->Triangle(lower[k], upper[k], lower[k1]);
    builder->Triangle(lower[k1], upper[k], upper[k1]);
  }
}

}  // namespace

TubeMesh MakeCapsuleTube(const Eigen::VectorXd& arc, const Eigen::VectorXd& radii, int sides,
                         int cap_rings, const Eigen::Matrix3d& to_scene) {
  assert(arc.size() >= 2 && radii.size() == arc.size() - 1 && sides >= 3 && cap_rings >= 1);
  assert(radii.minCoeff() > 0.0);
  const int joints = static_cast<int>(arc.size());
  const int last = joints - 1;
  TubeMesh mesh;
  Builder builder(&mesh, to_scene);
  const std::vector<Vector3d> around = Around(sides);
  // A ring of radius r at joint j, `lift` along +Y from it (a hemisphere's latitude: cos and sin
  // of its angle); normals radial tilted by the latitude, or `axial` (an annulus) if not zero.
  const auto ring = [&](int j, double r, double c, double s, double axial, int a, int b, float wb) {
    std::vector<uint32_t> vertices(sides);
    for (int k = 0; k < sides; ++k) {
      const Vector3d direction = c * around[k] + Vector3d(0.0, s, 0.0);
      const Vector3d normal = axial != 0.0 ? Vector3d(0.0, axial, 0.0) : direction;
      vertices[k] = builder.Add(Vector3d(0.0, arc[j], 0.0) + r * direction, normal, a, b, wb);
    }
    return vertices;
  };
  // A hemisphere at end joint j (sign -1: towards -Y at joint 0; +1: +Y at the last joint) of
  // radius r, skinned to j: its rings from the equator (excluded) to the pole, in that order.
  const auto cap = [&](int j, double r, double sign, std::vector<std::vector<uint32_t>>* rings,
                       uint32_t* pole) {
    for (int m = 1; m <= cap_rings; ++m) {
      const double latitude = 0.5 * M_PI * m / (cap_rings + 1);
      rings->push_back(ring(j, r, std::cos(latitude), sign * std::sin(latitude), 0.0, j, j, 0.0f));
    }
    const Vector3d normal(0.0, sign, 0.0);
    *pole = builder.Add(Vector3d(0.0, arc[j] + sign * r, 0.0), normal, j, j, 0.0f);
  };

  // The first cap, from its pole to its equator.
  std::vector<std::vector<uint32_t>> rings;
  uint32_t first_pole = 0;
  cap(0, radii[0], -1.0, &rings, &first_pole);
  std::reverse(rings.begin(), rings.end());
  for (int k = 0; k < sides; ++k) {
    const int k1 = (k + 1) % sides;
    builder.Triangle(first_pole, rings[0][k], rings[0][k1]);
  }
  for (size_t m = 1; m < rings.size(); ++m) JoinRings(rings[m - 1], rings[m], &builder);
  std::vector<uint32_t> previous = rings.back();
  // The side, joint after joint: the end rings fully to the end joints, the inner ones half to
  // each bone (as MakeTube's).
  for (int j = 0; j < joints; ++j) {
    const int a = j == 0 ? 0 : (j == last ? last : j - 1);
    const float wb = (j == 0 || j == last) ? 0.0f : 0.5f;
    const double below = radii[j == 0 ? 0 : j - 1], above = radii[j == last ? last - 1 : j];
    std::vector<uint32_t> side = ring(j, below, 1.0, 0.0, 0.0, a, j, wb);
    JoinRings(previous, side, &builder);
    if (above != below) {
      // The step between the two links' cylinders: a flat annulus facing the thinner link.
      const double facing = below > above ? 1.0 : -1.0;
      const std::vector<uint32_t> from = ring(j, below, 1.0, 0.0, facing, a, j, wb);
      const std::vector<uint32_t> to = ring(j, above, 1.0, 0.0, facing, a, j, wb);
      JoinRings(from, to, &builder);
      side = ring(j, above, 1.0, 0.0, 0.0, a, j, wb);
    }
    previous = std::move(side);
  }
  // The last cap, from its equator (the last ring) to its pole.
  rings.clear();
  uint32_t last_pole = 0;
  cap(last, radii[last - 1], 1.0, &rings, &last_pole);
  for (const std::vector<uint32_t>& latitude : rings) {
    JoinRings(previous, latitude, &builder);
    previous = latitude;
  }
  for (int k = 0; k < sides; ++k) {
    const int k1 = (k + 1) % sides;
    builder.Triangle(previous[k], last_pole, previous[k1]);
  }
  return mesh;
}

}  // namespace flexkin::gltf

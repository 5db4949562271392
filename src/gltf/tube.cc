#include "gltf/tube.h"

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

}  // namespace

TubeMesh MakeTube(const Eigen::VectorXd& arc, double radius, int sides,
                  const Eigen::Matrix3d& to_scene) {
  assert(arc.size() >= 2 && sides >= 3 && radius > 0.0);
  const int joints = static_cast<int>(arc.size());
  const int last = joints - 1;
  TubeMesh mesh;
  Builder builder(&mesh, to_scene);
  std::vector<Vector3d> around(sides);  // unit radial directions, about +Y
  for (int k = 0; k < sides; ++k) {
    const double angle = 2.0 * M_PI * k / sides;
    around[k] = Vector3d(std::cos(angle), 0.0, std::sin(angle));
  }

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

}  // namespace flexkin::gltf

#include "gltf/rig.h"

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>

namespace flexkin::gltf {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

// The smallest rotation taking unit vector `a` to unit vector `b`. Built from the half-way
// vector, which stays accurate close to a half turn (where 1 + a.b loses all its digits). For
// a half turn the axis is the one perpendicular to `a` closest to z, so a planar chain (z = 0)
// always turns about z and stays in its plane.
Quaterniond SmallestRotation(const Vector3d& a, const Vector3d& b) {
  const Vector3d sum = a + b;
  const double norm = sum.norm();
  if (norm < 1e-12) {
    Vector3d axis = Vector3d::UnitZ() - a.z() * a;
    if (axis.norm() < 0.5) axis = Vector3d::UnitX() - a.x() * a;
    axis.normalize();
    return Quaterniond(0.0, axis.x(), axis.y(), axis.z());
  }
  const Vector3d half = sum / norm;
  const Vector3d axis = a.cross(half);
  return Quaterniond(a.dot(half), axis.x(), axis.y(), axis.z()).normalized();
}

}  // namespace

Matrix3d QuaternionMatrix(double x, double y, double z, double w) {
  return Quaterniond(w, x, y, z).normalized().toRotationMatrix();
}

RigAnimation PoseChain(const std::vector<Points>& frames) {
  RigAnimation rig;
  assert(!frames.empty() && frames[0].rows() >= 2 && frames[0].cols() == 3);
  const int joints = static_cast<int>(frames[0].rows());
  const int num_frames = static_cast<int>(frames.size());
  rig.num_joints = joints;
  rig.num_frames = num_frames;
  rig.translation.assign(joints, std::vector<float>(3 * static_cast<size_t>(num_frames)));
  rig.rotation.assign(joints, std::vector<float>(4 * static_cast<size_t>(num_frames)));

  std::vector<Vector3d> dir(joints);          // dir[i]: unit vector of link i (1-based)
  std::vector<Quaterniond> world(joints);     // wanted world orientation of each joint
  std::vector<Quaterniond> previous(joints);  // last frame's stored local rotations
  Quaterniond root;                           // joint 0's orientation, carried over time
  Vector3d root_bone = Vector3d::UnitY();     // joint 0's bone direction in the last frame
  for (int f = 0; f < num_frames; ++f) {
    const Points& p = frames[f];
    assert(p.rows() == joints && p.cols() == 3);
    for (int i = 1; i < joints; ++i) {
      dir[i] = (p.row(i) - p.row(i - 1)).transpose();
      dir[i].normalize();
    }
    // Bones point from point j to point j+1: joint j's bone is link j+1.
    root = (f == 0 ? SmallestRotation(Vector3d::UnitY(), dir[1])
                   : SmallestRotation(root_bone, dir[1]) * root)
               .normalized();
    root_bone = dir[1];
    world[0] = root;
    for (int j = 1; j + 1 < joints; ++j) {
      world[j] = (SmallestRotation(dir[j], dir[j + 1]) * world[j - 1]).normalized();
    }
    world[joints - 1] = world[joints - 2];

    // Store, composing what was stored as a reader will: W and P are the parent's world
    // rotation and position built from the float32 values.
    Matrix3d parent_rotation = Matrix3d::Identity();
    Vector3d parent_position = Vector3d::Zero();
    for (int j = 0; j < joints; ++j) {
      Quaterniond local(parent_rotation.transpose() * world[j].toRotationMatrix());
      local.normalize();
      if (f > 0 && local.dot(previous[j]) < 0.0) local.coeffs() *= -1.0;
      float* q = &rig.rotation[j][4 * static_cast<size_t>(f)];
      q[0] = static_cast<float>(local.x());
      q[1] = static_cast<float>(local.y());
      q[2] = static_cast<float>(local.z());
      q[3] = static_cast<float>(local.w());
      previous[j] = Quaterniond(q[3], q[0], q[1], q[2]);

      const Vector3d offset =
          parent_rotation.transpose() * (p.row(j).transpose() - parent_position);
      float* t = &rig.translation[j][3 * static_cast<size_t>(f)];
      for (int k = 0; k < 3; ++k) t[k] = static_cast<float>(offset[k]);
      parent_position += parent_rotation * Vector3d(t[0], t[1], t[2]);
      parent_rotation = parent_rotation * QuaternionMatrix(q[0], q[1], q[2], q[3]);
    }
  }
  return rig;
}

}  // namespace flexkin::gltf

#include "gltf/rig.h"

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>

#include "flexkin/tree.h"

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

// A joint's world rotation and position as a reader composes them from the stored float32
// values.
struct Composed {
  Matrix3d rotation = Matrix3d::Identity();
  Vector3d position = Vector3d::Zero();
};

// Stores frame f of every joint: joint j, at `head.row(j)` with world orientation world[j], under
// joint parent[j] (-1: the skeleton's root; every parent before its children). Composes what was
// stored as a reader will, so that each translation is computed from the float32 rotations and
// translations of the joint's ancestors: the composed position is the wanted one to float32
// rounding of that translation alone. Quaternion signs stay continuous over time (`previous`).
void StorePose(int f, const Points& head, const std::vector<Quaterniond>& world,
               const std::vector<int>& parent, std::vector<Composed>* composed,
               std::vector<Quaterniond>* previous, RigAnimation* rig) {
  static const Composed kOrigin;
  for (size_t j = 0; j < world.size(); ++j) {
    const Composed& up = parent[j] < 0 ? kOrigin : (*composed)[parent[j]];
    Quaterniond local(up.rotation.transpose() * world[j].toRotationMatrix());
    local.normalize();
    if (f > 0 && local.dot((*previous)[j]) < 0.0) local.coeffs() *= -1.0;
    float* q = &rig->rotation[j][4 * static_cast<size_t>(f)];
    q[0] = static_cast<float>(local.x());
    q[1] = static_cast<float>(local.y());
    q[2] = static_cast<float>(local.z());
    q[3] = static_cast<float>(local.w());
    (*previous)[j] = Quaterniond(q[3], q[0], q[1], q[2]);

    const Vector3d offset = up.rotation.transpose() * (head.row(j).transpose() - up.position);
    float* t = &rig->translation[j][3 * static_cast<size_t>(f)];
    for (int k = 0; k < 3; ++k) t[k] = static_cast<float>(offset[k]);
    (*composed)[j].position = up.position + up.rotation * Vector3d(t[0], t[1], t[2]);
    (*composed)[j].rotation = up.rotation * QuaternionMatrix(q[0], q[1], q[2], q[3]);
  }
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
  std::vector<Composed> composed(joints);
  std::vector<int> chain_parent(joints);
  for (int j = 0; j < joints; ++j) chain_parent[j] = j - 1;
  Quaterniond root;                        // joint 0's orientation, carried over time
  Vector3d root_bone = Vector3d::UnitY();  // joint 0's bone direction in the last frame
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

    StorePose(f, p, world, chain_parent, &composed, &previous, &rig);
  }
  return rig;
}

}  // namespace flexkin::gltf

namespace flexkin::gltf {

TreeSkeleton MakeTreeSkeleton(const std::vector<int>& parents, const std::vector<int>& sliding) {
  const int points = static_cast<int>(parents.size());
  const std::vector<std::vector<int>> children = TreeChildren(parents);
  const int root = TreeRoot(parents);
  // The points in breadth-first order from the root, each point's children in index order.
  std::vector<int> order = {root};
  for (size_t k = 0; k < order.size(); ++k) {
    for (const int c : children[order[k]]) order.push_back(c);
  }
  TreeSkeleton s;
  std::vector<int> link_joint(points, 0);  // the joint of the link that ends at each point
  s.parent.push_back(-1);
  s.head.push_back(root);
  s.toward.push_back(children[root].empty() ? -1 : children[root].front());
  s.names.push_back("point_" + std::to_string(root));
  for (size_t k = 1; k < order.size(); ++k) {
    const int c = order[k], p = parents[c];
    link_joint[c] = static_cast<int>(s.head.size());
    s.parent.push_back(p == root ? 0 : link_joint[p]);
    s.head.push_back(p);
    s.toward.push_back(c);
    s.names.push_back("link_" + std::to_string(c));
  }
  for (size_t k = 1; k < order.size(); ++k) {
    const int c = order[k];
    if (!children[c].empty()) continue;
    s.parent.push_back(link_joint[c]);
    s.head.push_back(c);
    s.toward.push_back(-1);
    s.names.push_back("tip_" + std::to_string(c));
  }
  std::vector<char> slides(points, 0);
  for (const int c : sliding) slides[c] = 1;
  for (size_t k = 1; k < order.size(); ++k) {
    const int c = order[k];
    if (children[c].empty() || !slides[c]) continue;
    s.parent.push_back(link_joint[c]);
    s.head.push_back(c);
    s.toward.push_back(-1);
    s.names.push_back("slide_" + std::to_string(c));
  }
  return s;
}

RigAnimation PoseTree(const TreeSkeleton& skeleton, const std::vector<Points>& frames) {
  const int joints = static_cast<int>(skeleton.head.size());
  const int num_frames = static_cast<int>(frames.size());
  RigAnimation rig;
  rig.num_joints = joints;
  rig.num_frames = num_frames;
  rig.translation.assign(joints, std::vector<float>(3 * static_cast<size_t>(num_frames)));
  rig.rotation.assign(joints, std::vector<float>(4 * static_cast<size_t>(num_frames)));

  std::vector<Vector3d> bone(joints);         // each joint's bone direction (unit)
  std::vector<Quaterniond> world(joints);     // wanted world orientation of each joint
  std::vector<Quaterniond> previous(joints);  // last frame's stored local rotations
  std::vector<Composed> composed(joints);
  Points head(joints, 3);
  Quaterniond root;
  Vector3d root_bone = Vector3d::UnitY();
  for (int f = 0; f < num_frames; ++f) {
    const Points& p = frames[f];
    for (int j = 0; j < joints; ++j) {
      head.row(j) = p.row(skeleton.head[j]);
      const int to = skeleton.toward[j];
      // A tip continues its link; the root of a lone point (no children) keeps +Y.
      if (to < 0) {
        bone[j] = j > 0 ? bone[skeleton.parent[j]] : Vector3d::UnitY();
        continue;
      }
      const auto direction = [&](const Points& q) {
        return Vector3d((q.row(to) - q.row(skeleton.head[j])).transpose());
      };
      Vector3d d = direction(p);
      if (d.squaredNorm() == 0.0 && f == 0) {
        // A sliding link closed in the first frame: the direction it first opens in.
        for (int g = 1; g < num_frames && d.squaredNorm() == 0.0; ++g) d = direction(frames[g]);
        if (d.squaredNorm() == 0.0) d = j > 0 ? bone[skeleton.parent[j]] : Vector3d::UnitY();
      }
      if (d.squaredNorm() > 0.0) bone[j] = d.normalized();  // else the frame before's
    }
    root = (f == 0 ? SmallestRotation(Vector3d::UnitY(), bone[0])
                   : SmallestRotation(root_bone, bone[0]) * root)
               .normalized();
    root_bone = bone[0];
    world[0] = root;
    for (int j = 1; j < joints; ++j) {
      const int up = skeleton.parent[j];
      world[j] = (SmallestRotation(bone[up], bone[j]) * world[up]).normalized();
    }
    StorePose(f, head, world, skeleton.parent, &composed, &previous, &rig);
  }
  return rig;
}

}  // namespace flexkin::gltf

// WriteTreeGltf: a tree result's frames as a skinned, animated glTF 2.0 skeleton with a bone per
// link (docs/gltf-export.md, "Trees").
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/gltf.h"
#include "gltf/model.h"
#include "gltf/rig.h"
#include "gltf/tube.h"

namespace flexkin {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

std::string PointField(size_t f, Eigen::Index i) {
  return "frames[" + std::to_string(f) + "].points[" + std::to_string(i) + "]";
}

// Per point: 1 where the link into it slides (TreeResultFile::sliding).
std::vector<char> SlidingMask(const TreeResultFile& tree) {
  std::vector<char> slides(tree.parents.size(), 0);
  for (const int c : tree.sliding) slides[c] = 1;
  return slides;
}

// glTF's limits for a tree read and checked by ReadTreeResultFile: joints that 16-bit indices
// address, float32 coordinates, keyframe times, and a direction for every link in every frame.
void CheckTreeGltfLimits(const TreeResultFile& tree, const gltf::TreeSkeleton& skeleton,
                         const GltfOptions& options) {
  if (skeleton.head.size() >= static_cast<size_t>(gltf::kMaxJoints)) {
    throw InputError("parents", std::to_string(skeleton.head.size()) +
                                    " joints (a bone per link and a tip per leaf) is too many; "
                                    "glTF joint indices (16 bits) allow at most " +
                                    std::to_string(gltf::kMaxJoints - 1));
  }
  const double largest = 1e30 / options.scale;
  const std::vector<char> slides = SlidingMask(tree);
  for (size_t f = 0; f < tree.frames.size(); ++f) {
    const Points& p = tree.frames[f];
    for (Eigen::Index i = 0; i < p.rows(); ++i) {
      for (Eigen::Index k = 0; k < p.cols(); ++k) {
        if (std::abs(p(i, k)) > largest) {
          throw InputError(PointField(f, i) + "[" + std::to_string(k) + "]",
                           FormatNumber(p(i, k)) +
                               " is not valid; coordinates must fit in float32 (|x| <= " +
                               FormatNumber(largest) + " at this scale)");
        }
      }
      const int parent = tree.parents[i];
      if (parent >= 0 && !slides[i] && p.row(i) == p.row(parent)) {
        throw InputError(PointField(f, i), "coincides with its parent, point " +
                                               std::to_string(parent) +
                                               "; a link needs a direction");
      }
    }
  }
  const float last = static_cast<float>((tree.frames.size() - 1) / options.steps_per_second);
  if (!std::isfinite(last)) {
    throw InputError("steps_per_second", FormatNumber(options.steps_per_second) +
                                             " is too small: the last keyframe's time overflows "
                                             "float32; use a larger value");
  }
}

// The keyframe times: frame f at f / steps_per_second, float32, strictly increasing.
std::vector<float> TreeKeyframeTimes(size_t frames, double steps_per_second) {
  std::vector<float> times;
  for (size_t f = 0; f < frames; ++f) {
    times.push_back(static_cast<float>(f / steps_per_second));
    if (f > 0 && !(times[f] > times[f - 1])) {
      throw InputError("steps_per_second",
                       FormatNumber(steps_per_second) + " is too small for " +
                           std::to_string(frames) +
                           " frames: keyframe times round to the same float32; use a larger "
                           "value");
    }
  }
  return times;
}

tinygltf::Value TreeExtras(const TreeResultFile& tree, const gltf::TreeSkeleton& skeleton,
                           const GltfOptions& options, GltfUpAxis axis) {
  tinygltf::Value::Object info;
  info["format"] = tinygltf::Value(std::string("flexkin-gltf"));
  info["version"] = tinygltf::Value(1);
  info["topology"] = tinygltf::Value(std::string("tree"));
  info["dim"] = tinygltf::Value(tree.dim);
  info["up_axis"] = tinygltf::Value(std::string(GltfUpAxisName(axis)));
  info["scale"] = tinygltf::Value(options.scale);
  info["steps_per_second"] = tinygltf::Value(options.steps_per_second);
  info["num_points"] = tinygltf::Value(static_cast<int>(tree.parents.size()));
  info["method"] = tinygltf::Value(std::string(tree.robot ? "newton" : MethodName(tree.method)));
  tinygltf::Value::Array parents, heads;
  for (const int p : tree.parents) parents.emplace_back(p);
  for (const int h : skeleton.head) heads.emplace_back(h);
  info["parents"] = tinygltf::Value(std::move(parents));
  info["joint_points"] = tinygltf::Value(std::move(heads));
  if (!tree.sliding.empty()) {
    tinygltf::Value::Array sliding;
    for (const int c : tree.sliding) sliding.emplace_back(c);
    info["sliding"] = tinygltf::Value(std::move(sliding));
  }
  if (!tree.name.empty()) info["scenario"] = tinygltf::Value(tree.name);
  tinygltf::Value::Object extras;
  extras["flexkin"] = tinygltf::Value(std::move(info));
  return tinygltf::Value(std::move(extras));
}

// Each joint's frame-0 pose as a reader composes it from the stored float32 values (the bind
// pose), in the skeleton's space.
struct BindPose {
  std::vector<Matrix3d> rotation;
  std::vector<Vector3d> position;
};
BindPose ComposeBindPose(const gltf::TreeSkeleton& skeleton, const gltf::RigAnimation& rig) {
  BindPose pose;
  const size_t joints = skeleton.head.size();
  pose.rotation.resize(joints);
  pose.position.resize(joints);
  for (size_t j = 0; j < joints; ++j) {
    const float* q = rig.rotation[j].data();
    const float* t = rig.translation[j].data();
    const int up = skeleton.parent[j];
    const Matrix3d parent_rotation = up < 0 ? Matrix3d::Identity() : pose.rotation[up];
    const Vector3d parent_position = up < 0 ? Vector3d::Zero() : pose.position[up];
    pose.position[j] = parent_position + parent_rotation * Vector3d(t[0], t[1], t[2]);
    pose.rotation[j] = parent_rotation * gltf::QuaternionMatrix(q[0], q[1], q[2], q[3]);
  }
  return pose;
}

// A capsule per link in the bind pose, each skinned wholly to its link's bone (so it moves
// rigidly with it), and the inverse bind matrices of every joint.
void AddTreeMesh(const TreeResultFile& tree, const gltf::TreeSkeleton& skeleton,
                 const BindPose& bind, const GltfOptions& options, const Matrix3d& to_scene,
                 gltf::BufferWriter* buffer, tinygltf::Model* model) {
  const Points& first = tree.frames.front();
  const size_t joints = skeleton.head.size();
  // Each link's length in the bind pose: the first frame's; a sliding link's capsule is drawn as
  // long as the link is longest, its far half skinned to the joint at its end (the link's tip or
  // slide joint), whose bind pose is put there: the capsule stretches and shrinks with the link.
  std::vector<double> length(joints, 0.0);
  std::vector<int> end_joint(first.rows(), -1);
  for (size_t j = 0; j < joints; ++j) {
    if (skeleton.toward[j] < 0 && j > 0) end_joint[skeleton.head[j]] = static_cast<int>(j);
  }
  const std::vector<char> slides = SlidingMask(tree);
  double total = 0.0;
  int links = 0;
  for (size_t j = 0; j < joints; ++j) {
    if (j == 0 || skeleton.toward[j] < 0) continue;
    const int to = skeleton.toward[j], from = skeleton.head[j];
    length[j] = (first.row(to) - first.row(from)).norm();
    if (slides[to]) {
      for (const Points& p : tree.frames)
        length[j] = std::max(length[j], (p.row(to) - p.row(from)).norm());
    }
    total += length[j];
    if (length[j] > 0.0) ++links;
  }
  // The bind pose of each sliding link's end joint: on the capsule's far end.
  std::vector<Matrix3d> bind_rotation = bind.rotation;
  std::vector<Vector3d> bind_position = bind.position;
  for (size_t j = 1; j < joints; ++j) {
    const int to = skeleton.toward[j];
    if (to < 0 || !slides[to]) continue;
    const int e = end_joint[to];
    bind_rotation[e] = bind.rotation[j];
    bind_position[e] = bind.position[j] + bind.rotation[j] * Vector3d(0.0, length[j], 0.0);
  }
  const double thickest = std::min(0.25 * total / links, 0.02 * total);
  gltf::TubeMesh mesh;
  for (size_t j = 1; j < joints; ++j) {
    // (A sliding link of length 0 in every frame, a joint that never moved off its lower limit,
    // has nothing to draw.)
    if (skeleton.toward[j] < 0 || length[j] == 0.0) continue;
    const double radius =
        options.tube_radius > 0.0 ? options.tube_radius : std::min(thickest, 0.25 * length[j]);
    Eigen::VectorXd arc(2), radii(1);
    arc << 0.0, length[j];
    radii << radius;
    const gltf::TubeMesh capsule =
        gltf::MakeCapsuleTube(arc, radii, options.tube_sides, std::max(2, options.tube_sides / 4),
                              to_scene * bind.rotation[j]);
    const Vector3d offset = to_scene * bind.position[j];
    const uint32_t base = static_cast<uint32_t>(mesh.num_vertices());
    const int far = slides[skeleton.toward[j]] ? end_joint[skeleton.toward[j]] : -1;
    const Matrix3d to_link = (to_scene * bind.rotation[j]).inverse();
    for (int v = 0; v < capsule.num_vertices(); ++v) {
      for (int k = 0; k < 3; ++k) {
        mesh.positions.push_back(static_cast<float>(capsule.positions[3 * v + k] + offset[k]));
        mesh.normals.push_back(capsule.normals[3 * v + k]);
      }
      const Vector3d along =
          to_link * Vector3d(capsule.positions[3 * v], capsule.positions[3 * v + 1],
                             capsule.positions[3 * v + 2]);
      const int joint = far >= 0 && along.y() > 0.5 * length[j] ? far : static_cast<int>(j);
      mesh.joints.insert(mesh.joints.end(), {static_cast<uint16_t>(joint), 0, 0, 0});
      mesh.weights.insert(mesh.weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    }
    for (const uint32_t i : capsule.indices) mesh.indices.push_back(base + i);
  }
  gltf::AddSkinnedMesh(mesh, "tree", gltf::MakeMaterial("branches", {0.45, 0.62, 0.25}, 0.8),
                       buffer, model);

  // Inverse bind matrices: the inverse of each joint's bind pose mapped to the scene, column-major.
  std::vector<float> inverse_bind;
  for (size_t j = 0; j < joints; ++j) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = to_scene * bind_rotation[j];
    m.topRightCorner<3, 1>() = to_scene * bind_position[j];
    const Eigen::Matrix4d inverse = m.inverse();
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) inverse_bind.push_back(static_cast<float>(inverse(r, c)));
    }
  }
  model->skins[0].inverseBindMatrices =
      buffer->Accessor(buffer->View(inverse_bind, 0, "inverse bind matrices"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, joints);
}

}  // namespace

void WriteTreeGltf(const TreeResultFile& tree, const GltfOptions& options,
                   const std::string& path) {
  ThrowIfAny(options.Validate());
  ThrowIfAny(ValidateTreeResult(tree));
  internal::WriteTreeGltf(tree, options, path);
}

void internal::WriteTreeGltf(const TreeResultFile& tree, const GltfOptions& options,
                             const std::string& path) {
  const bool binary = gltf::IsBinaryPath(path);
  const gltf::TreeSkeleton skeleton = gltf::MakeTreeSkeleton(tree.parents, tree.sliding);
  CheckTreeGltfLimits(tree, skeleton, options);
  const std::vector<float> times = TreeKeyframeTimes(tree.frames.size(), options.steps_per_second);
  const GltfUpAxis axis = gltf::ResolvedUpAxis(options.up_axis, tree.dim);
  const int rows = static_cast<int>(tree.parents.size());

  std::vector<Points> frames;
  frames.reserve(tree.frames.size());
  for (const Points& p : tree.frames) {
    Points q = Points::Zero(rows, 3);
    q.leftCols(tree.dim) = p;
    frames.push_back(std::move(q));
  }
  const gltf::RigAnimation rig = gltf::PoseTree(skeleton, frames);
  const int joints = rig.num_joints;

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "flexkin";
  model.asset.extras = TreeExtras(tree, skeleton, options, axis);
  gltf::BufferWriter buffer(&model);

  // Nodes: 0 the "flexkin" node (axes and scale), 1 + j joint j (at rest in the first frame's
  // pose), then the mesh.
  tinygltf::Node root = gltf::FlexkinRootNode(axis, options.scale);
  root.children = {1};
  model.nodes.push_back(root);
  tinygltf::Skin skin;
  skin.name = "tree";
  skin.skeleton = 1;
  for (int j = 0; j < joints; ++j) {
    tinygltf::Node joint;
    joint.name = skeleton.names[j];
    const float* t = rig.translation[j].data();
    const float* q = rig.rotation[j].data();
    joint.translation = {t[0], t[1], t[2]};
    joint.rotation = {q[0], q[1], q[2], q[3]};
    model.nodes.push_back(joint);
    skin.joints.push_back(j + 1);
  }
  for (int j = 1; j < joints; ++j) model.nodes[1 + skeleton.parent[j]].children.push_back(j + 1);
  model.skins.push_back(skin);
  tinygltf::Scene scene;
  scene.name = tree.name.empty() ? "flexkin" : tree.name;
  scene.nodes = {0};
  if (options.include_mesh) {
    AddTreeMesh(tree, skeleton, ComposeBindPose(skeleton, rig), options,
                options.scale * gltf::UpRotation(axis), &buffer, &model);
    tinygltf::Node mesh;
    mesh.name = "tree_capsules";
    mesh.mesh = 0;
    mesh.skin = 0;
    model.nodes.push_back(mesh);
    scene.nodes.push_back(joints + 1);
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  tinygltf::Animation animation;
  animation.name = "motion";
  gltf::AddRigChannels(
      rig, times, [&](int j) { return skeleton.names[j]; }, &buffer, &animation);
  model.animations.push_back(animation);
  gltf::SaveModel(&model, binary, path);
}

}  // namespace flexkin

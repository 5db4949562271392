// WriteGltf: a result's frames as a skinned, animated glTF 2.0 skeleton (docs/gltf-export.md).
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/gltf.h"
#include "flexkin/propagate.h"
#include "gltf/model.h"
#include "gltf/rig.h"
#include "gltf/tube.h"
#include "io/atomic_file.h"
#include "io/collider_mesh.h"

namespace flexkin {
namespace {

using gltf::AddChannel;
using gltf::BufferWriter;
using gltf::kArrayBuffer;
using gltf::kElementArrayBuffer;
using gltf::kMaxJoints;
using gltf::MinMax;
using gltf::UpRotation;

std::string Index(const std::string& name, size_t i) {
  return name + "[" + std::to_string(i) + "]";
}

// Checks that a valid result (ValidateResult) can be exported: glTF's own limits (16-bit joint
// indices, float32 coordinates, a direction for every link); throws InputError naming the field
// otherwise.
void CheckGltfLimits(const ResultFile& file, double scale) {
  const RunResult& result = file.result;
  const Eigen::Index n = result.lengths.size();
  if (n + 1 > kMaxJoints) {
    throw InputError("link_lengths", std::to_string(n) +
                                         " links is too many; glTF joint indices "
                                         "(16 bits) allow at most " +
                                         std::to_string(kMaxJoints - 1));
  }
  // float32 overflows near 3.4e38; refuse long before.
  const double largest = 1e30 / scale;
  for (size_t f = 0; f < result.frames.size(); ++f) {
    const Points& p = result.frames[f].points;
    const std::string field = Index("frames", f) + ".points";
    for (Eigen::Index i = 0; i <= n; ++i) {
      for (int k = 0; k < file.dim; ++k) {
        if (std::abs(p(i, k)) > largest) {
          throw InputError(Index(Index(field, i), k),
                           FormatNumber(p(i, k)) +
                               " is not valid; coordinates must fit in float32 (|x| <= " +
                               FormatNumber(largest) + " at this scale)");
        }
      }
      if (i > 0 && p.row(i) == p.row(i - 1)) {
        throw InputError(Index(field, i), "coincides with point " + std::to_string(i - 1) +
                                              "; a link needs a direction");
      }
    }
  }
}

// The keyframe times, seconds, as float32; InputError if two round to the same value.
std::vector<float> KeyframeTimes(const RunResult& result, double steps_per_second) {
  std::vector<float> times;
  for (size_t f = 0; f < result.frames.size(); ++f) {
    times.push_back(static_cast<float>(result.frames[f].step / steps_per_second));
    if (!std::isfinite(times[f]) || (f > 0 && !(times[f] > times[f - 1]))) {
      throw InputError(
          "steps_per_second",
          FormatNumber(steps_per_second) +
              " is too small "
              "for step " +
              std::to_string(result.frames[f].step) +
              ": its keyframe "
              "time overflows float32 or rounds to the previous one; use a larger value");
    }
  }
  return times;
}

tinygltf::Value Extras(const ResultFile& file, const GltfOptions& options, GltfUpAxis axis) {
  tinygltf::Value::Object info;
  info["format"] = tinygltf::Value(std::string("flexkin-gltf"));
  info["version"] = tinygltf::Value(1);
  info["dim"] = tinygltf::Value(file.dim);
  info["up_axis"] = tinygltf::Value(std::string(GltfUpAxisName(axis)));
  info["scale"] = tinygltf::Value(options.scale);
  info["steps_per_second"] = tinygltf::Value(options.steps_per_second);
  info["num_links"] = tinygltf::Value(static_cast<int>(file.result.lengths.size()));
  info["method"] = tinygltf::Value(std::string(MethodName(file.result.method)));
  if (!file.scenario_name.empty()) info["scenario"] = tinygltf::Value(file.scenario_name);
  tinygltf::Value::Object extras;
  extras["flexkin"] = tinygltf::Value(std::move(info));
  return tinygltf::Value(std::move(extras));
}

// Links of a radius (a result's "link_radii", at least one > 0): the tube, unless a radius is
// given for it, is the links' capsules (gltf::MakeCapsuleTube).
bool HasCapsules(const ResultFile& file) {
  return file.link_radii.size() > 0 && file.link_radii.maxCoeff() > 0.0;
}

// The capsules' radii: each link's own; a link of radius 0 (a line, which the figures draw without
// a capsule) the smaller of the tube's default radius `thin` and the least radius > 0, so that the
// tube stays closed and such a link is never thicker than one with a capsule.
Eigen::VectorXd CapsuleRadii(const Eigen::VectorXd& radii, double thin) {
  double least = HUGE_VAL;
  for (const double r : radii) {
    if (r > 0.0) least = std::min(least, r);
  }
  Eigen::VectorXd out = radii;
  for (double& r : out) {
    if (!(r > 0.0)) r = std::min(thin, least);
  }
  return out;
}

// Rings of latitude on each end's hemisphere besides its equator: about a quarter of the rings'
// vertices, at least 2.
int CapRings(int sides) { return std::max(2, sides / 4); }

void AddMesh(const ResultFile& file, const GltfOptions& options, const Eigen::Matrix3d& to_scene,
             BufferWriter* buffer, tinygltf::Model* model) {
  const Eigen::VectorXd& lengths = file.result.lengths;
  const int n = static_cast<int>(lengths.size());
  Eigen::VectorXd arc(n + 1);
  arc[0] = 0.0;
  for (int i = 0; i < n; ++i) arc[i + 1] = arc[i] + lengths[i];
  const double radius =
      options.tube_radius > 0.0 ? options.tube_radius : std::min(0.25 * arc[n] / n, 0.02 * arc[n]);
  const gltf::TubeMesh tube =
      options.tube_radius > 0.0 || !HasCapsules(file)
          ? gltf::MakeTube(arc, radius, options.tube_sides, to_scene)
          : gltf::MakeCapsuleTube(arc, CapsuleRadii(file.link_radii, radius), options.tube_sides,
                                  CapRings(options.tube_sides), to_scene);
  gltf::AddSkinnedMesh(tube, "chain", gltf::MakeMaterial("rope", {0.80, 0.45, 0.15}, 0.7), buffer,
                       model);

  // Inverse bind matrices: the rest pose puts joint j at (0, arc[j], 0) in the skeleton's space,
  // which the "flexkin" node maps to the scene by to_scene; the inverse, column-major.
  const Eigen::Matrix3d from_scene = to_scene.inverse();
  std::vector<float> inverse_bind;
  for (int j = 0; j <= n; ++j) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = from_scene;
    m(1, 3) = -arc[j];
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) inverse_bind.push_back(static_cast<float>(m(r, c)));
    }
  }
  model->skins[0].inverseBindMatrices =
      buffer->Accessor(buffer->View(inverse_bind, 0, "inverse bind matrices"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, n + 1);
}

// Each collider as a mesh node "collider_k" under the "flexkin" node (node 0), so in the chain's
// up axis and scale: its surface (io/collider_mesh.h) in flexkin's coordinates, every vertex on
// it; a half-space as a square of its plane, 20 times the motion's extent across, about the
// plane's point nearest the motion's centre. A keyframed collider's surface is where it is at
// the first frame; its node's animation (AddColliderMotion) carries it. Returns the node of each
// keyframed collider, with the collider's index.
std::vector<std::pair<int, size_t>> AddColliders(const ResultFile& file, BufferWriter* buffer,
                                                 tinygltf::Model* model) {
  std::vector<std::pair<int, size_t>> moving;
  if (file.colliders.empty()) return moving;
  Eigen::Vector3d lo, hi;
  BoundsOfMotion(file, &lo, &hi);
  const double extent = std::max((hi - lo).norm(), file.result.lengths.sum());
  const int material = static_cast<int>(model->materials.size());
  tinygltf::Material stone = gltf::MakeMaterial("collider", {0.62, 0.62, 0.60}, 0.9);
  stone.doubleSided = true;  // a half-space's square is seen from both sides
  model->materials.push_back(stone);
  for (size_t k = 0; k < file.colliders.size(); ++k) {
    const Collider& given = file.colliders[k];
    const Collider collider = given.motion && !file.result.frames.empty()
                                  ? ColliderAt(given, double(file.result.frames[0].step))
                                  : given;
    const ColliderMesh mesh = MeshOfCollider(collider, 48, 0.5 * (lo + hi), 10.0 * extent);
    const std::string name = "collider_" + std::to_string(k);
    std::vector<float> positions;
    for (const Eigen::Vector3d& v : mesh.vertices) {
      for (int c = 0; c < 3; ++c) positions.push_back(static_cast<float>(v[c]));
    }
    std::vector<uint32_t> indices;
    for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
    std::vector<double> min, max;
    MinMax(positions, 3, &min, &max);
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] = buffer->Accessor(
        buffer->View(positions, kArrayBuffer, name + " positions"), 0,
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, mesh.vertices.size(), min, max);
    primitive.indices = buffer->Accessor(
        buffer->View(indices, kElementArrayBuffer, name + " indices"), 0,
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.material = material;
    tinygltf::Mesh gltf_mesh;
    gltf_mesh.name = name + " (" + ColliderShapeName(collider.shape) + ")";
    gltf_mesh.primitives.push_back(primitive);
    model->meshes.push_back(gltf_mesh);
    tinygltf::Node node;
    node.name = name;
    node.mesh = static_cast<int>(model->meshes.size() - 1);
    model->nodes.push_back(node);
    model->nodes[0].children.push_back(static_cast<int>(model->nodes.size() - 1));
    if (given.motion) moving.emplace_back(static_cast<int>(model->nodes.size() - 1), k);
  }
  return moving;
}

// The motion of a keyframed collider's node: at each recorded frame f, the rotation and the
// translation of M(t_f) M(t_0)^-1 (M(t) the collider's motion's pose at time t, frame f's step),
// which carry its surface from where the first frame has it.
void AddColliderMotion(const ResultFile& file, const Collider& collider, int node, int input,
                       BufferWriter* buffer, tinygltf::Animation* animation) {
  const size_t frames = file.result.frames.size();
  std::vector<float> translations, rotations;
  for (const Eigen::Isometry3d& t : MovesFromFirstFrame(collider, file)) {
    Eigen::Quaterniond q(t.linear());
    q.normalize();
    for (int c = 0; c < 3; ++c) translations.push_back(static_cast<float>(t.translation()[c]));
    for (const double v : {q.x(), q.y(), q.z(), q.w()}) rotations.push_back(static_cast<float>(v));
  }
  const std::string name = "collider node " + std::to_string(node);
  const int translation =
      buffer->Accessor(buffer->View(translations, 0, name + " translation"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, frames);
  const int rotation = buffer->Accessor(buffer->View(rotations, 0, name + " rotation"), 0,
                                        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, frames);
  AddChannel(input, translation, node, "translation", animation);
  AddChannel(input, rotation, node, "rotation", animation);
}

}  // namespace

void WriteGltf(const ResultFile& file, const GltfOptions& options, const std::string& path) {
  ThrowIfAny(options.Validate());
  ThrowIfAny(ValidateResult(file));
  internal::WriteGltf({file}, options, path);
}

void internal::WriteGltf(const CheckedDrawing& drawing, const GltfOptions& options,
                         const std::string& path) {
  const ResultFile& file = drawing.result;
  const bool binary = gltf::IsBinaryPath(path);
  CheckGltfLimits(file, options.scale);
  const RunResult& result = file.result;
  const std::vector<float> times = KeyframeTimes(result, options.steps_per_second);
  const int n = static_cast<int>(result.lengths.size());
  const GltfUpAxis axis = gltf::ResolvedUpAxis(options.up_axis, file.dim);

  std::vector<Points> frames;
  frames.reserve(result.frames.size());
  for (const Frame& frame : result.frames) {
    Points p = Points::Zero(n + 1, 3);
    p.leftCols(file.dim) = frame.points;
    frames.push_back(std::move(p));
  }
  const gltf::RigAnimation rig = gltf::PoseChain(frames);

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "flexkin";
  model.asset.extras = Extras(file, options, axis);
  BufferWriter buffer(&model);

  // Nodes: 0 the "flexkin" node (axes and scale), 1 + j joint j, n + 2 the tube, then the
  // colliders (children of node 0).
  tinygltf::Node root = gltf::FlexkinRootNode(axis, options.scale);
  root.children = {1};
  model.nodes.push_back(root);
  tinygltf::Skin skin;
  skin.name = "chain";
  skin.skeleton = 1;
  for (int j = 0; j <= n; ++j) {
    tinygltf::Node joint;
    joint.name = "joint_" + std::to_string(j);
    if (j > 0) joint.translation = {0.0, result.lengths[j - 1], 0.0};
    if (j < n) joint.children = {j + 2};
    model.nodes.push_back(joint);
    skin.joints.push_back(j + 1);
  }
  model.skins.push_back(skin);
  tinygltf::Scene scene;
  scene.name = file.scenario_name.empty() ? "flexkin" : file.scenario_name;
  scene.nodes = {0};
  if (options.include_mesh) {
    AddMesh(file, options, options.scale * UpRotation(axis), &buffer, &model);
    tinygltf::Node tube;
    tube.name = "chain_tube";
    tube.mesh = 0;
    tube.skin = 0;
    model.nodes.push_back(tube);
    scene.nodes.push_back(n + 2);
  }
  const std::vector<std::pair<int, size_t>> moving_colliders = AddColliders(file, &buffer, &model);
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  // The animation: one input (the keyframe times), a translation and a rotation channel per joint.
  tinygltf::Animation animation;
  animation.name = "motion";
  const int input = gltf::AddRigChannels(
      rig, times, [](int j) { return "joint_" + std::to_string(j); }, &buffer, &animation);
  for (const auto& [node, k] : moving_colliders) {
    AddColliderMotion(file, file.colliders[k], node, input, &buffer, &animation);
  }
  model.animations.push_back(animation);

  gltf::SaveModel(&model, binary, path);
}

}  // namespace flexkin

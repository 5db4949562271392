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
#include "gltf/rig.h"
#include "gltf/tube.h"
#include "io/atomic_file.h"
#include "io/collider_mesh.h"

namespace flexkin {
namespace {

// glTF enums (the specification's numbers).
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
// The most joints that the unsigned 16-bit indices of JOINTS_0 can address.
constexpr int kMaxJoints = 65536;

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

// True for a .glb path, false for .gltf (any case); InputError("path") for anything else.
bool IsBinaryPath(const std::string& path) {
  const size_t dot = path.rfind('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == "glb") return true;
  if (ext == "gltf") return false;
  throw InputError("path",
                   "\"" + path +
                       "\" has no .gltf or .glb extension; the extension "
                       "chooses the format (.glb binary, .gltf JSON with an embedded buffer)");
}

// Appends arrays to the model's one buffer, one buffer view each, 4-byte aligned.
class BufferWriter {
 public:
  explicit BufferWriter(tinygltf::Model* model) : model_(model) { model_->buffers.resize(1); }

  template <typename T>
  int View(const std::vector<T>& values, int target, const std::string& name) {
    std::vector<unsigned char>& data = model_->buffers[0].data;
    data.resize((data.size() + 3) / 4 * 4, 0);
    tinygltf::BufferView view;
    view.name = name;
    view.buffer = 0;
    view.byteOffset = data.size();
    view.byteLength = values.size() * sizeof(T);
    if (target != 0) view.target = target;
    const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
    data.insert(data.end(), bytes, bytes + view.byteLength);
    model_->bufferViews.push_back(view);
    return static_cast<int>(model_->bufferViews.size() - 1);
  }

  // An accessor of `count` elements of `type` (TINYGLTF_TYPE_*) in `view` at `byte_offset`.
  int Accessor(int view, size_t byte_offset, int component_type, int type, size_t count,
               std::vector<double> min = {}, std::vector<double> max = {}) {
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.byteOffset = byte_offset;
    accessor.componentType = component_type;
    accessor.type = type;
    accessor.count = count;
    accessor.minValues = std::move(min);
    accessor.maxValues = std::move(max);
    model_->accessors.push_back(accessor);
    return static_cast<int>(model_->accessors.size() - 1);
  }

 private:
  tinygltf::Model* model_;
};

// Per-component minimum and maximum of float vectors of `width` components.
void MinMax(const std::vector<float>& values, int width, std::vector<double>* min,
            std::vector<double>* max) {
  min->assign(width, HUGE_VAL);
  max->assign(width, -HUGE_VAL);
  for (size_t i = 0; i < values.size(); ++i) {
    const int k = static_cast<int>(i % width);
    (*min)[k] = std::min<double>((*min)[k], values[i]);
    (*max)[k] = std::max<double>((*max)[k], values[i]);
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

// The "flexkin" node's linear map from flexkin's coordinates to the scene's: rotation R, scale s.
Eigen::Matrix3d UpRotation(GltfUpAxis axis) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  // (x, y, z) -> (x, z, -y): a quarter turn about x, clockwise seen from +x.
  if (axis == GltfUpAxis::kZ) r << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return r;
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
  const size_t vertices = tube.num_vertices();

  tinygltf::Primitive primitive;
  std::vector<double> min, max;
  MinMax(tube.positions, 3, &min, &max);
  primitive.attributes["POSITION"] =
      buffer->Accessor(buffer->View(tube.positions, kArrayBuffer, "positions"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices, min, max);
  primitive.attributes["NORMAL"] =
      buffer->Accessor(buffer->View(tube.normals, kArrayBuffer, "normals"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices);
  primitive.attributes["JOINTS_0"] =
      buffer->Accessor(buffer->View(tube.joints, kArrayBuffer, "joints"), 0,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, vertices);
  primitive.attributes["WEIGHTS_0"] =
      buffer->Accessor(buffer->View(tube.weights, kArrayBuffer, "weights"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, vertices);
  primitive.indices = buffer->Accessor(buffer->View(tube.indices, kElementArrayBuffer, "indices"),
                                       0, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                       TINYGLTF_TYPE_SCALAR, tube.indices.size());
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.material = 0;

  tinygltf::Material material;
  material.name = "rope";
  material.pbrMetallicRoughness.baseColorFactor = {0.80, 0.45, 0.15, 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.7;
  model->materials.push_back(material);

  tinygltf::Mesh mesh;
  mesh.name = "chain";
  mesh.primitives.push_back(primitive);
  model->meshes.push_back(mesh);

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

// A LINEAR sampler of `output` over the keyframe times `input`, driving `property` of `node`.
void AddChannel(int input, int output, int node, const char* property,
                tinygltf::Animation* animation) {
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation->samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(animation->samplers.size() - 1);
  channel.target_node = node;
  channel.target_path = property;
  animation->channels.push_back(channel);
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
  tinygltf::Material stone;
  stone.name = "collider";
  stone.pbrMetallicRoughness.baseColorFactor = {0.62, 0.62, 0.60, 1.0};
  stone.pbrMetallicRoughness.metallicFactor = 0.0;
  stone.pbrMetallicRoughness.roughnessFactor = 0.9;
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
  const bool binary = IsBinaryPath(path);
  CheckGltfLimits(file, options.scale);
  const RunResult& result = file.result;
  const std::vector<float> times = KeyframeTimes(result, options.steps_per_second);
  const int n = static_cast<int>(result.lengths.size());
  const GltfUpAxis axis = options.up_axis != GltfUpAxis::kAuto
                              ? options.up_axis
                              : (file.dim == 2 ? GltfUpAxis::kY : GltfUpAxis::kZ);

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
  tinygltf::Node root;
  root.name = "flexkin";
  if (axis == GltfUpAxis::kZ) root.rotation = {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  if (options.scale != 1.0) root.scale = {options.scale, options.scale, options.scale};
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
  std::vector<double> min, max;
  MinMax(times, 1, &min, &max);
  const int input =
      buffer.Accessor(buffer.View(times, 0, "keyframe times"), 0, TINYGLTF_COMPONENT_TYPE_FLOAT,
                      TINYGLTF_TYPE_SCALAR, times.size(), min, max);
  for (int j = 0; j <= n; ++j) {
    const int translation = buffer.Accessor(
        buffer.View(rig.translation[j], 0, "joint_" + std::to_string(j) + " translation"), 0,
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, times.size());
    const int rotation =
        buffer.Accessor(buffer.View(rig.rotation[j], 0, "joint_" + std::to_string(j) + " rotation"),
                        0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, times.size());
    AddChannel(input, translation, j + 1, "translation", &animation);
    AddChannel(input, rotation, j + 1, "rotation", &animation);
  }
  for (const auto& [node, k] : moving_colliders) {
    AddColliderMotion(file, file.colliders[k], node, input, &buffer, &animation);
  }
  model.animations.push_back(animation);

  WriteFileAtomically(path, [&](std::ostream& out) {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary)) {
      throw std::runtime_error("tinygltf could not serialize the glTF model");
    }
  });
}

}  // namespace flexkin

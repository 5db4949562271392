// ReadGltfJointPositions: a glTF file's skin joints, posed by its first animation at each keyframe.
#include "gltf/reader.h"

#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "flexkin/error.h"
#include "flexkin/gltf.h"
#include "gltf/rig.h"

namespace flexkin {
namespace {

using Eigen::Matrix4d;

std::string Index(const std::string& name, size_t i) {
  return name + "[" + std::to_string(i) + "]";
}

tinygltf::Model Load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::system_error(errno ? errno : EIO, std::generic_category(), path);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::system_error(errno ? errno : EIO, std::generic_category(), path);
  if (bytes.size() >= 0xFFFFFFFFu) throw InputError("", "the file is too large (4 GiB or more)");

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  if (bytes.compare(0, 4, "glTF") == 0) {
    ok = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                     reinterpret_cast<const unsigned char*>(bytes.data()),
                                     static_cast<unsigned int>(bytes.size()));
  } else {
    const size_t slash = path.rfind('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
    ok = loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                    static_cast<unsigned int>(bytes.size()), dir);
  }
  if (!ok) throw InputError("", "not a valid glTF file: " + (err.empty() ? warn : err));
  return model;
}

// The float values of accessor `index` of `components` components each, or InputError.
std::vector<float> ReadFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& field) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
    throw InputError(field, "accessor " + std::to_string(index) + " does not exist");
  }
  const tinygltf::Accessor& accessor = model.accessors[index];
  const std::string where = Index("accessors", index);
  if (accessor.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || accessor.sparse.isSparse ||
      tinygltf::GetNumComponentsInType(accessor.type) != components) {
    throw InputError(where, "only dense float accessors of " + std::to_string(components) +
                                " components are supported here");
  }
  if (accessor.bufferView < 0 ||
      accessor.bufferView >= static_cast<int>(model.bufferViews.size())) {
    throw InputError(where + ".bufferView", "does not exist");
  }
  const tinygltf::BufferView& view = model.bufferViews[accessor.bufferView];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size())) {
    throw InputError(Index("bufferViews", accessor.bufferView) + ".buffer", "does not exist");
  }
  const std::vector<unsigned char>& data = model.buffers[view.buffer].data;
  const size_t element = sizeof(float) * components;
  const int stride = accessor.ByteStride(view);
  if (stride <= 0) throw InputError(where, "invalid byte stride");
  const size_t start = view.byteOffset + accessor.byteOffset;
  const size_t count = accessor.count;
  if (count > 0 && (start + (count - 1) * static_cast<size_t>(stride) + element >
                    std::min(data.size(), view.byteOffset + view.byteLength))) {
    throw InputError(where, "reaches past the end of its buffer view");
  }
  std::vector<float> values(count * components);
  for (size_t i = 0; i < count; ++i) {
    std::memcpy(&values[i * components], data.data() + start + i * stride, element);
  }
  return values;
}

// One animated property of a node.
struct Track {
  int node = -1;
  int components = 0;  // 3 (translation, scale) or 4 (rotation)
  bool rotation = false;
  bool step = false;          // STEP, else LINEAR
  std::vector<float> times;   // increasing
  std::vector<float> values;  // components per time
  std::string path;           // "translation", "rotation" or "scale"
};

// The track's value at time t: held before the first and after the last keyframe; exactly the
// keyframe's value at a keyframe; linear in between (normalized linear interpolation would do
// for rotations between keyframes this close, but slerp is what glTF specifies).
std::vector<double> Sample(const Track& track, double t) {
  const int c = track.components;
  const auto& times = track.times;
  auto value = [&](size_t k) {
    return std::vector<double>(track.values.begin() + k * c, track.values.begin() + (k + 1) * c);
  };
  if (t <= times.front()) return value(0);
  if (t >= times.back()) return value(times.size() - 1);
  const size_t k = std::upper_bound(times.begin(), times.end(), t) - times.begin() - 1;
  if (t == times[k] || track.step) return value(k);
  const double u = (t - times[k]) / (times[k + 1] - times[k]);
  const std::vector<double> a = value(k), b = value(k + 1);
  std::vector<double> out(c);
  if (track.rotation) {
    const Eigen::Quaterniond qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]);
    const Eigen::Quaterniond q = qa.normalized().slerp(u, qb.normalized());
    return {q.x(), q.y(), q.z(), q.w()};
  }
  for (int i = 0; i < c; ++i) out[i] = (1.0 - u) * a[i] + u * b[i];
  return out;
}

std::vector<Track> ReadTracks(const tinygltf::Model& model) {
  std::vector<Track> tracks;
  if (model.animations.empty()) return tracks;
  const tinygltf::Animation& animation = model.animations[0];
  for (size_t c = 0; c < animation.channels.size(); ++c) {
    const tinygltf::AnimationChannel& channel = animation.channels[c];
    const std::string field = Index("animations[0].channels", c);
    if (channel.target_path == "weights") continue;
    if (channel.sampler < 0 || channel.sampler >= static_cast<int>(animation.samplers.size())) {
      throw InputError(field + ".sampler", "does not exist");
    }
    if (channel.target_node < 0 || channel.target_node >= static_cast<int>(model.nodes.size())) {
      throw InputError(field + ".target.node", "does not exist");
    }
    const tinygltf::AnimationSampler& sampler = animation.samplers[channel.sampler];
    Track track;
    track.node = channel.target_node;
    track.path = channel.target_path;
    track.rotation = track.path == "rotation";
    track.components = track.rotation ? 4 : 3;
    if (track.path != "translation" && track.path != "rotation" && track.path != "scale") {
      throw InputError(field + ".target.path", "\"" + track.path + "\" is not supported");
    }
    if (sampler.interpolation != "LINEAR" && sampler.interpolation != "STEP") {
      throw InputError(Index("animations[0].samplers", channel.sampler) + ".interpolation",
                       "\"" + sampler.interpolation + "\" is not supported; LINEAR or STEP");
    }
    track.step = sampler.interpolation == "STEP";
    track.times = ReadFloats(model, sampler.input, 1, field + ".input");
    track.values = ReadFloats(model, sampler.output, track.components, field + ".output");
    if (track.times.empty() || track.values.size() != track.times.size() * track.components ||
        !std::is_sorted(track.times.begin(), track.times.end())) {
      throw InputError(Index("animations[0].samplers", channel.sampler),
                       "needs as many outputs as inputs, and increasing input times");
    }
    // A NaN would pass the order check and send Sample past the last keyframe.
    if (const auto bad = std::find_if(track.times.begin(), track.times.end(),
                                      [](float t) { return !std::isfinite(t); });
        bad != track.times.end()) {
      throw InputError(Index("animations[0].samplers", channel.sampler) + ".input",
                       "time " + std::to_string(bad - track.times.begin()) + " is " +
                           std::to_string(*bad) + "; expected finite, increasing times (seconds)");
    }
    tracks.push_back(std::move(track));
  }
  return tracks;
}

// The node's local transform from its own TRS or matrix, overridden by animated values.
Matrix4d LocalMatrix(const tinygltf::Node& node, const std::vector<double>* translation,
                     const std::vector<double>* rotation, const std::vector<double>* scale) {
  if (node.matrix.size() == 16 && !translation && !rotation && !scale) {
    return Eigen::Map<const Matrix4d>(node.matrix.data());  // column-major, as glTF
  }
  auto pick = [](const std::vector<double>* animated, const std::vector<double>& own,
                 std::vector<double> fallback) {
    if (animated) return *animated;
    return own.size() == fallback.size() ? own : fallback;
  };
  const std::vector<double> t = pick(translation, node.translation, {0, 0, 0});
  const std::vector<double> r = pick(rotation, node.rotation, {0, 0, 0, 1});
  const std::vector<double> s = pick(scale, node.scale, {1, 1, 1});
  Matrix4d m = Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = gltf::QuaternionMatrix(r[0], r[1], r[2], r[3]) *
                            Eigen::Vector3d(s[0], s[1], s[2]).asDiagonal();
  m.topRightCorner<3, 1>() = Eigen::Vector3d(t[0], t[1], t[2]);
  return m;
}

}  // namespace

GltfJointMotion ReadGltfJointPositions(const std::string& path) {
  const tinygltf::Model model = Load(path);
  if (model.skins.empty() || model.skins[0].joints.empty()) {
    throw InputError("skins", "the file has no skin with joints; nothing to read");
  }
  const std::vector<int>& joints = model.skins[0].joints;
  const int num_nodes = static_cast<int>(model.nodes.size());
  std::vector<int> parent(num_nodes, -1);
  for (int i = 0; i < num_nodes; ++i) {
    for (const int child : model.nodes[i].children) {
      if (child < 0 || child >= num_nodes || parent[child] != -1 || child == i) {
        throw InputError(Index("nodes", i) + ".children",
                         "child " + std::to_string(child) + " does not exist or has two parents");
      }
      parent[child] = i;
    }
  }
  for (const int joint : joints) {
    if (joint < 0 || joint >= num_nodes) {
      throw InputError("skins[0].joints", "node " + std::to_string(joint) + " does not exist");
    }
  }
  // Parents first, so that one pass composes the hierarchy; a cycle leaves nodes unordered.
  std::vector<int> order;
  for (int i = 0; i < num_nodes; ++i) {
    if (parent[i] == -1) order.push_back(i);
  }
  for (size_t k = 0; k < order.size(); ++k) {
    for (const int child : model.nodes[order[k]].children) order.push_back(child);
  }
  if (static_cast<int>(order.size()) != num_nodes) {
    throw InputError("nodes", "the node hierarchy has a cycle");
  }

  const std::vector<Track> tracks = ReadTracks(model);
  GltfJointMotion motion;
  for (const Track& track : tracks) {
    motion.times.insert(motion.times.end(), track.times.begin(), track.times.end());
  }
  std::sort(motion.times.begin(), motion.times.end());
  motion.times.erase(std::unique(motion.times.begin(), motion.times.end()), motion.times.end());
  if (motion.times.empty()) motion.times = {0.0};

  // The mapping back to flexkin's coordinates, if WriteGltf wrote the file.
  Eigen::Matrix3d to_flexkin = Eigen::Matrix3d::Identity();
  motion.dim = 3;
  if (model.asset.extras.Has("flexkin")) {
    const tinygltf::Value& info = model.asset.extras.Get("flexkin");
    const tinygltf::Value& dim = info.Get("dim");
    const tinygltf::Value& scale = info.Get("scale");
    const tinygltf::Value& up = info.Get("up_axis");
    if (!dim.IsNumber() || !scale.IsNumber() || !up.IsString() ||
        (dim.GetNumberAsInt() != 2 && dim.GetNumberAsInt() != 3) ||
        !(scale.GetNumberAsDouble() > 0.0)) {
      throw InputError("asset.extras.flexkin", "needs dim (2 or 3), scale (> 0) and up_axis");
    }
    motion.dim = dim.GetNumberAsInt();
    const GltfUpAxis axis = ParseGltfUpAxis(up.Get<std::string>(), "asset.extras.flexkin.up_axis");
    if (axis == GltfUpAxis::kZ) to_flexkin << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // (x, z, -y) back
    to_flexkin /= scale.GetNumberAsDouble();
    const tinygltf::Value& heads = info.Get("joint_points");
    if (heads.IsArray()) {
      for (size_t j = 0; j < heads.ArrayLen(); ++j) {
        const tinygltf::Value& h = heads.Get(static_cast<int>(j));
        if (!h.IsNumber() || h.GetNumberAsInt() < 0) {
          throw InputError("asset.extras.flexkin.joint_points[" + std::to_string(j) + "]",
                           "is not a point index; expected an integer >= 0");
        }
        motion.joint_points.push_back(h.GetNumberAsInt());
      }
      if (motion.joint_points.size() != joints.size()) {
        throw InputError("asset.extras.flexkin.joint_points",
                         "has " + std::to_string(motion.joint_points.size()) +
                             " entries; expected one per joint of the skin (" +
                             std::to_string(joints.size()) + ")");
      }
    }
  }

  std::vector<Matrix4d> global(num_nodes);
  for (const double t : motion.times) {
    std::vector<std::vector<double>> animated(3 * static_cast<size_t>(num_nodes));
    std::vector<char> has(3 * static_cast<size_t>(num_nodes), 0);
    for (const Track& track : tracks) {
      const int slot = track.path == "translation" ? 0 : (track.rotation ? 1 : 2);
      animated[3 * track.node + slot] = Sample(track, t);
      has[3 * track.node + slot] = 1;
    }
    for (const int i : order) {
      auto get = [&](int slot) { return has[3 * i + slot] ? &animated[3 * i + slot] : nullptr; };
      const Matrix4d local = LocalMatrix(model.nodes[i], get(0), get(1), get(2));
      global[i] = parent[i] == -1 ? local : global[parent[i]] * local;
    }
    Points p(joints.size(), motion.dim);
    for (size_t j = 0; j < joints.size(); ++j) {
      const Eigen::Vector3d world = global[joints[j]].topRightCorner<3, 1>();
      p.row(j) = (to_flexkin * world).head(motion.dim).transpose();
    }
    motion.positions.push_back(std::move(p));
  }
  return motion;
}

gltf::SkinnedMeshRestPose gltf::ReadSkinnedMeshRestPose(const std::string& path) {
  const tinygltf::Model model = Load(path);
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const tinygltf::Node& node = model.nodes[i];
    if (node.mesh < 0 || node.skin < 0) continue;
    const std::string field = Index("nodes", i);
    if (node.mesh >= static_cast<int>(model.meshes.size()) ||
        model.meshes[node.mesh].primitives.empty()) {
      throw InputError(field + ".mesh",
                       "mesh " + std::to_string(node.mesh) + " does not exist or has no primitive");
    }
    if (node.skin >= static_cast<int>(model.skins.size())) {
      throw InputError(field + ".skin", "skin " + std::to_string(node.skin) + " does not exist");
    }
    const tinygltf::Primitive& primitive = model.meshes[node.mesh].primitives[0];
    const std::string where = Index("meshes", node.mesh) + ".primitives[0].attributes";
    SkinnedMeshRestPose pose;
    const auto vectors = [&](const char* name, std::vector<Eigen::Vector3d>* out) {
      const auto it = primitive.attributes.find(name);
      if (it == primitive.attributes.end()) return false;
      const std::vector<float> values = ReadFloats(model, it->second, 3, where + "." + name);
      for (size_t k = 0; k + 2 < values.size(); k += 3) {
        out->emplace_back(values[k], values[k + 1], values[k + 2]);
      }
      return true;
    };
    if (!vectors("POSITION", &pose.positions)) {
      throw InputError(where, "has no POSITION; a mesh needs its vertices");
    }
    vectors("NORMAL", &pose.normals);
    const tinygltf::Skin& skin = model.skins[node.skin];
    const std::vector<float> matrices = ReadFloats(
        model, skin.inverseBindMatrices, 16, Index("skins", node.skin) + ".inverseBindMatrices");
    for (size_t k = 0; k + 15 < matrices.size(); k += 16) {
      // Column-major, as glTF stores them.
      pose.inverse_bind_matrices.push_back(
          Eigen::Map<const Eigen::Matrix4f>(&matrices[k]).cast<double>());
    }
    return pose;
  }
  throw InputError("nodes", "no node has a mesh and a skin; nothing to read");
}

}  // namespace flexkin

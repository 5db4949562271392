#pragma once
// What the glTF writers of chains (writer.cc) and trees (tree_writer.cc) share: the model's one
// buffer, the animation's channels, the scene's axes and the file's format by its extension.

#include <tiny_gltf.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "flexkin/gltf.h"
#include "gltf/rig.h"
#include "gltf/tube.h"

namespace flexkin::gltf {

// glTF enums (the specification's numbers).
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
// The most joints that the unsigned 16-bit indices of JOINTS_0 can address.
constexpr int kMaxJoints = 65536;

// True for a .glb path, false for .gltf (any case); InputError("path") for anything else.
bool IsBinaryPath(const std::string& path);

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
            std::vector<double>* max);

// The "flexkin" node's linear map from flexkin's coordinates to the scene's: rotation R, scale s.
Eigen::Matrix3d UpRotation(GltfUpAxis axis);

// A LINEAR sampler of `output` over the keyframe times `input`, driving `property` of `node`.
void AddChannel(int input, int output, int node, const char* property,
                tinygltf::Animation* animation);

// The root node "flexkin" of a written file: the axes' rotation (GltfUpAxis) and the scale.
tinygltf::Node FlexkinRootNode(GltfUpAxis axis, double scale);

// The axis a result of `dim` dimensions is written with (kAuto: y for 2D, z for 3D).
GltfUpAxis ResolvedUpAxis(GltfUpAxis axis, int dim);

// The keyframe times (one input accessor, with its bounds) and a LINEAR translation and rotation
// channel for every joint j of `rig`, driving node j + 1 (the joints follow the "flexkin" node);
// `name(j)` names each joint's buffer views. Returns the input accessor.
int AddRigChannels(const RigAnimation& rig, const std::vector<float>& times,
                   const std::function<std::string(int)>& name, BufferWriter* buffer,
                   tinygltf::Animation* animation);

// A material of base colour `rgb`, not metallic, of `roughness`.
tinygltf::Material MakeMaterial(const std::string& name, const std::array<double, 3>& rgb,
                                double roughness);

// Adds `mesh` to the model as the mesh `name` of one primitive (POSITION with its bounds, NORMAL,
// JOINTS_0, WEIGHTS_0, triangles) in `material`, appended to the model's materials; returns the
// mesh's index.
int AddSkinnedMesh(const TubeMesh& mesh, const std::string& name,
                   const tinygltf::Material& material, BufferWriter* buffer,
                   tinygltf::Model* model);

// Writes the model whole or not at all (WriteFileAtomically): binary for .glb, JSON with the
// buffer embedded for .gltf.
void SaveModel(tinygltf::Model* model, bool binary, const std::string& path);

}  // namespace flexkin::gltf

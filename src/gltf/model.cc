#include "gltf/model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <ostream>
#include <stdexcept>

#include "flexkin/error.h"
#include "io/atomic_file.h"

namespace flexkin::gltf {

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

Eigen::Matrix3d UpRotation(GltfUpAxis axis) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  // (x, y, z) -> (x, z, -y): a quarter turn about x, clockwise seen from +x.
  if (axis == GltfUpAxis::kZ) r << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  return r;
}

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

tinygltf::Node FlexkinRootNode(GltfUpAxis axis, double scale) {
  tinygltf::Node root;
  root.name = "flexkin";
  if (axis == GltfUpAxis::kZ) root.rotation = {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
  if (scale != 1.0) root.scale = {scale, scale, scale};
  return root;
}

GltfUpAxis ResolvedUpAxis(GltfUpAxis axis, int dim) {
  if (axis != GltfUpAxis::kAuto) return axis;
  return dim == 2 ? GltfUpAxis::kY : GltfUpAxis::kZ;
}

int AddRigChannels(const RigAnimation& rig, const std::vector<float>& times,
                   const std::function<std::string(int)>& name, BufferWriter* buffer,
                   tinygltf::Animation* animation) {
  std::vector<double> min, max;
  MinMax(times, 1, &min, &max);
  const int input =
      buffer->Accessor(buffer->View(times, 0, "keyframe times"), 0, TINYGLTF_COMPONENT_TYPE_FLOAT,
                       TINYGLTF_TYPE_SCALAR, times.size(), min, max);
  for (int j = 0; j < rig.num_joints; ++j) {
    const int translation =
        buffer->Accessor(buffer->View(rig.translation[j], 0, name(j) + " translation"), 0,
                         TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, times.size());
    const int rotation =
        buffer->Accessor(buffer->View(rig.rotation[j], 0, name(j) + " rotation"), 0,
                         TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, times.size());
    AddChannel(input, translation, j + 1, "translation", animation);
    AddChannel(input, rotation, j + 1, "rotation", animation);
  }
  return input;
}

tinygltf::Material MakeMaterial(const std::string& name, const std::array<double, 3>& rgb,
                                double roughness) {
  tinygltf::Material material;
  material.name = name;
  material.pbrMetallicRoughness.baseColorFactor = {rgb[0], rgb[1], rgb[2], 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = roughness;
  return material;
}

int AddSkinnedMesh(const TubeMesh& mesh, const std::string& name,
                   const tinygltf::Material& material, BufferWriter* buffer,
                   tinygltf::Model* model) {
  const size_t vertices = mesh.num_vertices();
  tinygltf::Primitive primitive;
  std::vector<double> min, max;
  MinMax(mesh.positions, 3, &min, &max);
  primitive.attributes["POSITION"] =
      buffer->Accessor(buffer->View(mesh.positions, kArrayBuffer, "positions"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices, min, max);
  primitive.attributes["NORMAL"] =
      buffer->Accessor(buffer->View(mesh.normals, kArrayBuffer, "normals"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertices);
  primitive.attributes["JOINTS_0"] =
      buffer->Accessor(buffer->View(mesh.joints, kArrayBuffer, "joints"), 0,
                       TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, vertices);
  primitive.attributes["WEIGHTS_0"] =
      buffer->Accessor(buffer->View(mesh.weights, kArrayBuffer, "weights"), 0,
                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, vertices);
  primitive.indices = buffer->Accessor(buffer->View(mesh.indices, kElementArrayBuffer, "indices"),
                                       0, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                       TINYGLTF_TYPE_SCALAR, mesh.indices.size());
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.material = static_cast<int>(model->materials.size());
  model->materials.push_back(material);
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = name;
  gltf_mesh.primitives.push_back(primitive);
  model->meshes.push_back(gltf_mesh);
  return static_cast<int>(model->meshes.size() - 1);
}

void SaveModel(tinygltf::Model* model, bool binary, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(model, out, /*prettyPrint=*/!binary, binary)) {
      throw std::runtime_error("tinygltf could not serialize the glTF model");
    }
  });
}

}  // namespace flexkin::gltf

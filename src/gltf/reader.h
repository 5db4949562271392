#pragma once
// What the tests read of a glTF file besides its joints' motion (ReadGltfJointPositions,
// include/flexkin/gltf.h): the rest pose of its skinned mesh.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace flexkin::gltf {

// The first skinned mesh of a file (the first node with a mesh and a skin), as stored: its first
// primitive's vertices and normals in the skin's bind space (for a file of WriteGltf, the scene's:
// glTF's axes, metres), and its skin's inverse bind matrices, one per joint in the skin's order.
struct SkinnedMeshRestPose {
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector3d> normals;  // empty if the primitive has none
  std::vector<Eigen::Matrix4d> inverse_bind_matrices;
};

// Reads it from a .gltf or .glb file. Throws std::system_error if the file cannot be read,
// InputError (naming the field) if it is not valid glTF, has no skinned mesh, or its accessors are
// not dense float ones of the expected types.
SkinnedMeshRestPose ReadSkinnedMeshRestPose(const std::string& path);

}  // namespace flexkin::gltf

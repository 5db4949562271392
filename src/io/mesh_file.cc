// A mesh collider's file (flexkin/colliders.h ReadColliderMeshFile): STL, OBJ or any format
// assimp reads, its triangles in one mesh, vertices at the same place joined (an STL repeats
// every vertex in each of its triangles), then checked and built by MakeColliderMesh.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "flexkin/colliders.h"

namespace flexkin {

std::shared_ptr<const ColliderMeshData> ReadColliderMeshFile(const std::string& path,
                                                             const std::string& file,
                                                             const std::string& field,
                                                             std::vector<Problem>* problems) {
  const std::string quoted = "\"" + file + "\"";
  const char* expected = "a readable STL or OBJ file of a closed triangle mesh";
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      const int error = errno;
      problems->emplace_back(field, "cannot be read from " + path + ": " + std::strerror(error),
                             quoted, expected);
      return nullptr;
    }
  }
  Assimp::Importer importer;
  // Node transforms applied (a scene of several placed meshes reads as one), polygons split into
  // triangles; points and lines are left out below.
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices);
  if (scene == nullptr) {
    problems->emplace_back(
        field, "is not a mesh file assimp can read (" + path + "): " + importer.GetErrorString(),
        quoted, expected);
    return nullptr;
  }
  std::map<std::array<double, 3>, int> index_of;
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 3>> faces;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::vector<int> joined(mesh->mNumVertices);
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D& v = mesh->mVertices[i];
      const std::array<double, 3> p = {v.x, v.y, v.z};
      const auto [it, added] = index_of.emplace(p, static_cast<int>(points.size()));
      if (added) points.push_back(p);
      joined[i] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      faces.push_back(
          {joined[face.mIndices[0]], joined[face.mIndices[1]], joined[face.mIndices[2]]});
    }
  }
  MeshVertices vertices(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) vertices(i, k) = points[i][k];
  }
  MeshTriangles triangles(faces.size(), 3);
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) triangles(f, k) = faces[f][k];
  }
  return MakeColliderMesh(std::move(vertices), std::move(triangles), file, field, problems);
}

}  // namespace flexkin

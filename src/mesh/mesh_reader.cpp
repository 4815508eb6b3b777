// ReadTriangleMesh: the only assimp includer (STYLE H.10). Flattens the node hierarchy
// (aiProcess_PreTransformVertices) and keeps triangle primitives only.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <map>
#include <stdexcept>

#include "mesh/mesh.h"

namespace surge {

TriangleMesh ReadTriangleMesh(const std::string& path) {
  Assimp::Importer importer;
  // Drop points and lines (SortByPType + RemoveComponent would also work; we just skip them).
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_PreTransformVertices | aiProcess_SortByPType;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene == nullptr) {
    throw std::runtime_error("cannot read mesh file '" + path + "': " + importer.GetErrorString());
  }
  TriangleMesh mesh;
  std::map<std::array<double, 3>, int> welded;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* am = scene->mMeshes[m];
    // Weld vertices with bitwise-equal positions: assimp keeps STL corners apart when their face
    // normals differ, and the closedness check and inside test need shared edges.
    std::vector<int> index(am->mNumVertices);
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& a = am->mVertices[v];
      const std::array<double, 3> key = {a.x, a.y, a.z};
      const auto [it, inserted] = welded.try_emplace(key, static_cast<int>(mesh.vertices.size()));
      if (inserted) mesh.vertices.emplace_back(a.x, a.y, a.z);
      index[v] = it->second;
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      mesh.triangles.push_back(
          {index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
    }
  }
  if (mesh.triangles.empty()) {
    throw std::runtime_error("mesh file '" + path + "' contains no triangles");
  }
  return mesh;
}

}  // namespace surge

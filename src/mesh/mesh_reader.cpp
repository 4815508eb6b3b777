// ReadTriangleMesh: the only assimp includer (STYLE H.10). Walks the node hierarchy, applies the
// accumulated node transforms, keeps triangle primitives only and records one part per mesh name.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <map>
#include <stdexcept>
#include <string>

#include "mesh/mesh.h"

namespace surge {
namespace {

struct Builder {
  const aiScene* scene = nullptr;
  TriangleMesh mesh;
  std::map<std::array<double, 3>, int> welded;   // vertex position -> index
  std::map<std::string, int> part_of_name;       // mesh name -> part index

  int PartOf(const aiMesh& am) {
    const std::string name(am.mName.C_Str());
    if (name.empty()) {  // unnamed meshes each get their own part, named at the end
      mesh.part_names.emplace_back();
      return static_cast<int>(mesh.part_names.size()) - 1;
    }
    const auto [it, inserted] =
        part_of_name.try_emplace(name, static_cast<int>(mesh.part_names.size()));
    if (inserted) mesh.part_names.push_back(name);
    return it->second;
  }

  void AddMesh(const aiMesh& am, const aiMatrix4x4& transform) {
    const int part = PartOf(am);
    // Weld vertices with bitwise-equal positions: assimp keeps STL corners apart when their face
    // normals differ, and the closedness check and inside test need shared edges.
    std::vector<int> index(am.mNumVertices);
    for (unsigned v = 0; v < am.mNumVertices; ++v) {
      const aiVector3D a = transform * am.mVertices[v];
      const std::array<double, 3> key = {a.x, a.y, a.z};
      const auto [it, inserted] = welded.try_emplace(key, static_cast<int>(mesh.vertices.size()));
      if (inserted) mesh.vertices.emplace_back(a.x, a.y, a.z);
      index[v] = it->second;
    }
    for (unsigned f = 0; f < am.mNumFaces; ++f) {
      const aiFace& face = am.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      mesh.triangles.push_back(
          {index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
      mesh.part.push_back(part);
    }
  }

  // Depth first, children in file order; `parent` is the product of the ancestors' transforms.
  void AddNode(const aiNode& node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      AddMesh(*scene->mMeshes[node.mMeshes[i]], transform);
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) AddNode(*node.mChildren[c], transform);
  }
};

}  // namespace

TriangleMesh ReadTriangleMesh(const std::string& path) {
  Assimp::Importer importer;
  // No aiProcess_PreTransformVertices: it joins meshes that share a material, which would merge
  // the parts. The node transforms are applied in Builder::AddNode instead.
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error("cannot read mesh file '" + path + "': " + importer.GetErrorString());
  }
  Builder builder;
  builder.scene = scene;
  builder.AddNode(*scene->mRootNode, aiMatrix4x4());
  if (builder.mesh.triangles.empty()) {
    throw std::runtime_error("mesh file '" + path + "' contains no triangles");
  }
  // Drop the parts whose meshes held no triangles (points or lines only), renumber, and name the
  // unnamed ones after their final index.
  TriangleMesh& mesh = builder.mesh;
  std::vector<int> used(mesh.part_names.size(), 0);
  for (const int p : mesh.part) used[p] = 1;
  std::vector<int> renumber(mesh.part_names.size(), -1);
  std::vector<std::string> names;
  for (size_t p = 0; p < used.size(); ++p) {
    if (!used[p]) continue;
    renumber[p] = static_cast<int>(names.size());
    const std::string& name = mesh.part_names[p];
    names.push_back(name.empty() ? "part" + std::to_string(names.size()) : name);
  }
  for (int& p : mesh.part) p = renumber[p];
  mesh.part_names = std::move(names);
  return std::move(mesh);
}

}  // namespace surge

// ReadTriangleMesh: the only assimp includer (STYLE H.10). Walks the node hierarchy, applies the
// accumulated node transforms, keeps triangle primitives only and records one part per mesh name.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace surge {
namespace {

// How far into a PLY file its "end_header" line must appear [bytes]: a header lists a few element
// and property lines (comments included, kilobytes at most).
constexpr size_t kPlyHeaderBytes = 65536;

struct Builder {
  std::string path;  // for error messages
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
      // A NaN or infinite coordinate (an OBJ "v nan 0 0", a float overflow like 1e999) would
      // break the weld map's ordering and every later geometric test: reject the file.
      if (!std::isfinite(a.x) || !std::isfinite(a.y) || !std::isfinite(a.z)) {
        throw std::runtime_error("mesh file '" + path + "': vertex " + std::to_string(v + 1) +
                                 " of mesh '" + am.mName.C_Str() + "' is not finite (" +
                                 std::to_string(a.x) + ", " + std::to_string(a.y) + ", " +
                                 std::to_string(a.z) + ")");
      }
      const std::array<double, 3> key = {a.x, a.y, a.z};
      const auto [it, inserted] = welded.try_emplace(key, static_cast<int>(mesh.vertices.size()));
      if (inserted) mesh.vertices.emplace_back(a.x, a.y, a.z);
      index[v] = it->second;
    }
    for (unsigned f = 0; f < am.mNumFaces; ++f) {
      const aiFace& face = am.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      for (unsigned k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= am.mNumVertices) {
          throw std::runtime_error("mesh file '" + path + "': face " + std::to_string(f + 1) +
                                   " of mesh '" + am.mName.C_Str() + "' refers to vertex " +
                                   std::to_string(face.mIndices[k] + 1) + " of " +
                                   std::to_string(am.mNumVertices));
        }
      }
      mesh.triangles.push_back(
          {index[face.mIndices[0]], index[face.mIndices[1]], index[face.mIndices[2]]});
      mesh.part.push_back(part);
    }
  }

  // Depth first, children in file order; `parent` is the product of the ancestors' transforms.
  void AddNode(const aiNode& node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 transform = parent * node.mTransformation;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      if (node.mMeshes[i] >= scene->mNumMeshes || scene->mMeshes[node.mMeshes[i]] == nullptr) {
        throw std::runtime_error("mesh file '" + path + "': node '" + node.mName.C_Str() +
                                 "' refers to a mesh that is not in the file");
      }
      AddMesh(*scene->mMeshes[node.mMeshes[i]], transform);
    }
    for (unsigned c = 0; c < node.mNumChildren; ++c) AddNode(*node.mChildren[c], transform);
  }
};

// Throws naming the file and line unless `head` (the first kPlyHeaderBytes of the file) starts
// with a well-formed PLY header (Bourke's PLY format): "ply", one "format <ascii|binary_*> 1.0",
// then only "comment"/"obj_info" lines, "element <name> <count>" and "property <type> <name>" or
// "property list <type> <type> <name>" lines, up to "end_header".
void CheckPlyHeader(const std::string& path, const std::string& head) {
  static const std::set<std::string> kTypes = {
      "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
      "int16", "uint16", "int32", "uint32", "float32", "float64"};
  const auto fail = [&](int line, const std::string& what) {
    throw std::runtime_error("cannot read mesh file '" + path + "': line " + std::to_string(line) +
                             ": " + what);
  };
  std::istringstream lines(head);
  std::string text;
  int line = 0;
  bool format = false;
  while (std::getline(lines, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    // Printable ASCII, spaces and tabs only: assimp 5.2 splits header lines at '\n' alone, so
    // "end_header\v..." (a vertical tab where the newline belongs) passed the word check below
    // and its reader then looped forever (found by fuzz_mesh's mutation run).
    for (const char c : text) {
      if (c != '\t' && (c < 0x20 || c > 0x7e)) {
        fail(line, "control or non-ASCII character (byte " +
                       std::to_string(static_cast<unsigned char>(c)) + ") in the PLY header");
      }
    }
    std::istringstream words(text);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (line == 1) {
      if (w.size() != 1 || w[0] != "ply") fail(line, "a PLY file starts with a line \"ply\"");
      continue;
    }
    if (w.empty()) fail(line, "empty line in the PLY header");
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (w.size() != 1) fail(line, "\"end_header\" must be alone on its line");
      if (!format) fail(line, "PLY header without a format line");
      return;
    }
    if (w[0] == "format") {
      if (format || w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        fail(line, "expected one \"format ascii|binary_little_endian|binary_big_endian 1.0\"");
      format = true;
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string::npos ||
          w[2].size() > 10)
        fail(line, "expected \"element <name> <count>\"");
    } else if (w[0] == "property") {
      const bool list = w.size() == 5 && w[1] == "list" && kTypes.count(w[2]) && kTypes.count(w[3]);
      const bool scalar = w.size() == 3 && kTypes.count(w[1]);
      if (!list && !scalar)
        fail(line, "expected \"property <type> <name>\" or \"property list <type> <type> <name>\"");
    } else {
      fail(line, "unknown PLY header line \"" + w[0].substr(0, 40) + "\"");
    }
  }
  fail(line, "PLY header without an end_header line in its first " +
                 std::to_string(kPlyHeaderBytes) + " bytes");
}

}  // namespace

TriangleMesh ReadTriangleMesh(const std::string& path) {
  // Only regular files (or links to one): assimp would block forever reading a named pipe and
  // read a device such as /dev/zero without end.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    const bool exists = std::filesystem::exists(path, ec);
    throw std::runtime_error("cannot read mesh file '" + path + "': " +
                             (exists ? "not a regular file" : "no such file"));
  }
  // assimp 5.2's PLY reader loops forever on a header without "end_header" or with a malformed
  // line (fuzz_mesh hangs): check the header of anything named .ply or starting with "ply".
  {
    std::ifstream in(path, std::ios::binary);
    std::string head(kPlyHeaderBytes, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (ext == ".ply" || head.rfind("ply", 0) == 0) CheckPlyHeader(path, head);
  }
  Assimp::Importer importer;
  // No aiProcess_PreTransformVertices: it joins meshes that share a material, which would merge
  // the parts. The node transforms are applied in Builder::AddNode instead.
  // Import with validation only (indices out of range), reject faces without vertices, repair
  // the primitive-type flags, and only then post-process: a broken PLY gave a face with no
  // indices and a POLYGON flag without polygons, and Debian's assimp, built with assertions,
  // aborted the whole process in Triangulate on that (fuzz_mesh finding). The post-processing
  // steps and their order are the same as ReadFile(path, flags) would apply.
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error("cannot read mesh file '" + path + "': " + importer.GetErrorString());
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    aiMesh* am = scene->mMeshes[m];
    unsigned types = 0;
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const unsigned n = am->mFaces[f].mNumIndices;
      if (n == 0 || am->mFaces[f].mIndices == nullptr) {
        throw std::runtime_error("mesh file '" + path + "': face " + std::to_string(f + 1) +
                                 " of mesh '" + am->mName.C_Str() + "' has no vertices");
      }
      types |= n == 1 ? aiPrimitiveType_POINT
                      : n == 2 ? aiPrimitiveType_LINE
                               : n == 3 ? aiPrimitiveType_TRIANGLE : aiPrimitiveType_POLYGON;
    }
    am->mPrimitiveTypes = types;
  }
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                       aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error("cannot read mesh file '" + path + "': " + importer.GetErrorString());
  }
  Builder builder;
  builder.path = path;
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

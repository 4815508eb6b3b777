// ReadTriangleMesh: the only assimp includer (STYLE H.10). Walks the node hierarchy, applies the
// accumulated node transforms, keeps triangle primitives only and records one part per mesh name.
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
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

// What a PLY header declares: the body's encoding and, per element, its count and properties.
struct PlyProperty {
  bool list = false;
  std::string count_type;  // list only
  std::string type;        // the scalar's, or the list items'
};
struct PlyElement {
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};
struct PlyLayout {
  std::string format;     // ascii, binary_little_endian or binary_big_endian
  size_t body = 0;        // byte offset of the body (after the end_header line)
  int header_lines = 0;
  std::vector<PlyElement> elements;
};

// Longest list (polygon) a PLY body may hold: assimp 5.2 reads a list's items one by one, so a
// count of 2^31 (fuzz_mesh) kept it busy for hours.
constexpr uint64_t kPlyMaxListLength = 65536;

size_t PlyTypeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "double" || t == "float64") return 8;
  return 4;  // int, uint, float, int32, uint32, float32
}

// Throws naming the file and line unless `head` (the first kPlyHeaderBytes of the file) starts
// with a well-formed PLY header (Bourke's PLY format): "ply", one "format <ascii|binary_*> 1.0",
// then only "comment"/"obj_info" lines, "element <name> <count>" and "property <type> <name>" or
// "property list <type> <type> <name>" lines, up to "end_header". Returns what it declares.
PlyLayout CheckPlyHeader(const std::string& path, const std::string& head) {
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
  PlyLayout layout;
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
      for (const PlyElement& e : layout.elements) {
        if (e.count > 0 && e.properties.empty()) fail(line, "an element without properties");
      }
      layout.body = lines.tellg() < 0 ? head.size() : size_t(lines.tellg());
      layout.header_lines = line;
      return layout;
    }
    if (w[0] == "format") {
      if (format || w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        fail(line, "expected one \"format ascii|binary_little_endian|binary_big_endian 1.0\"");
      format = true;
      layout.format = w[1];
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string::npos ||
          w[2].size() > 10)
        fail(line, "expected \"element <name> <count>\"");
      layout.elements.push_back(PlyElement{std::stoull(w[2]), {}});
    } else if (w[0] == "property") {
      const bool list = w.size() == 5 && w[1] == "list" && kTypes.count(w[2]) && kTypes.count(w[3]);
      const bool scalar = w.size() == 3 && kTypes.count(w[1]);
      if (!list && !scalar)
        fail(line, "expected \"property <type> <name>\" or \"property list <type> <type> <name>\"");
      if (layout.elements.empty()) fail(line, "a property before any element");
      layout.elements.back().properties.push_back(
          list ? PlyProperty{true, w[2], w[3]} : PlyProperty{false, "", w[1]});
    } else {
      fail(line, "unknown PLY header line \"" + w[0].substr(0, 40) + "\"");
    }
  }
  fail(line, "PLY header without an end_header line in its first " +
                 std::to_string(kPlyHeaderBytes) + " bytes");
  return layout;  // not reached: fail throws
}

// Throws naming the file (and for ASCII the line) unless the body of a PLY file holds what its
// header declares: every element instance, each scalar a finite number, each list count a
// non-negative integer that fits its type and at most kPlyMaxListLength, followed by that many
// numbers. assimp 5.2 loops forever or for hours on a token that is not a number ("inf") or on
// a list count of 2^31 (fuzz_mesh mutation runs), so it only sees bodies that pass.
void CheckPlyBody(const std::string& path, const std::string& file, const PlyLayout& layout) {
  const auto fail = [&](const std::string& what) {
    throw std::runtime_error("cannot read mesh file '" + path + "': " + what);
  };
  const auto max_of = [](const std::string& t) -> uint64_t {
    const size_t size = PlyTypeSize(t);
    const bool is_signed = t[0] != 'u';
    return (uint64_t(1) << (8 * size - (is_signed ? 1 : 0))) - 1;
  };
  if (layout.format == "ascii") {
    std::istringstream lines(file.substr(layout.body));
    std::string text;
    int line = layout.header_lines;
    for (const PlyElement& e : layout.elements) {
      for (uint64_t k = 0; k < e.count; ++k) {
        ++line;
        if (!std::getline(lines, text)) {
          fail("line " + std::to_string(line) + ": the body ends before the " +
               std::to_string(e.count) + " instances the header declares");
        }
        std::istringstream words(text);
        std::string word;
        const auto number = [&](const char* what) {
          if (!(words >> word)) fail("line " + std::to_string(line) + ": missing " + what);
          char* end = nullptr;
          const double v = std::strtod(word.c_str(), &end);
          if (end != word.c_str() + word.size() || !std::isfinite(v)) {
            fail("line " + std::to_string(line) + ": \"" + word.substr(0, 40) +
                 "\" is not a finite number");
          }
          return v;
        };
        for (const PlyProperty& p : e.properties) {
          if (!p.list) {
            number("value");
            continue;
          }
          const double n = number("list count");
          if (n < 0 || n != std::floor(n) || n > double(max_of(p.count_type)) ||
              n > double(kPlyMaxListLength)) {
            fail("line " + std::to_string(line) + ": list count " + word.substr(0, 40) +
                 " is not an integer from 0 to " +
                 std::to_string(std::min(max_of(p.count_type), kPlyMaxListLength)));
          }
          for (uint64_t i = 0; i < uint64_t(n); ++i) number("list item");
        }
        if (words >> word) {
          fail("line " + std::to_string(line) + ": more values than the header declares");
        }
      }
    }
    return;
  }
  // Binary: walk the instances; list counts are read in the declared type and byte order.
  const bool little = layout.format == "binary_little_endian";
  size_t at = layout.body;
  for (const PlyElement& e : layout.elements) {
    for (uint64_t k = 0; k < e.count; ++k) {
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          at += PlyTypeSize(p.type);
          continue;
        }
        const size_t size = PlyTypeSize(p.count_type);
        if (at + size > file.size()) {
          fail("the body ends before the " + std::to_string(e.count) +
               " instances the header declares (" + std::to_string(file.size()) + " bytes)");
        }
        uint64_t raw = 0;
        for (size_t b = 0; b < size; ++b) {
          const uint64_t byte = static_cast<unsigned char>(file[at + (little ? b : size - 1 - b)]);
          raw |= byte << (8 * b);
        }
        const bool negative = p.count_type[0] != 'u' && (raw >> (8 * size - 1)) != 0;
        if (negative || raw > kPlyMaxListLength) {
          fail("a list count at byte " + std::to_string(at) + " is " +
               (negative ? std::string("negative") : std::to_string(raw)) + " (at most " +
               std::to_string(kPlyMaxListLength) + ")");
        }
        at += size + raw * PlyTypeSize(p.type);
      }
      if (at > file.size()) {
        fail("the body ends before the " + std::to_string(e.count) +
             " instances the header declares (" + std::to_string(file.size()) + " bytes)");
      }
    }
  }
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
    if (ext == ".ply" || head.rfind("ply", 0) == 0) {
      const PlyLayout layout = CheckPlyHeader(path, head);
      std::string file = std::move(head);  // and the rest of it: the body is checked too
      file.append(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      CheckPlyBody(path, file, layout);
    }
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

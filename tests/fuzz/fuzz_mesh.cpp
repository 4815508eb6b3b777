// Fuzz target: mesh reader (ReadTriangleMesh through assimp) and what the scene builder does with
// a mesh that reads: bounding box, open-edge count, inside test and the signed-distance field
// (MeshDistanceField). Input: byte 0 picks the file extension (.stl, .obj, .ply, .gltf by
// byte % 4), the rest is the file. Contract checked: a file that cannot be used is rejected with
// an exception whose message names the file (ReadTriangleMesh: std::runtime_error;
// MeshDistanceField: std::invalid_argument); a mesh that reads has finite vertices, in-range
// triangle indices and one part per triangle; a crash, hang or sanitizer report is a finding.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "contact/mesh_distance.h"
#include "fuzz/fuzz_util.h"
#include "mesh/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* const kExt[] = {".stl", ".obj", ".ply", ".gltf"};
  const std::string path = surge::fuzz::ScratchPath("mesh", kExt[data[0] % 4]);
  surge::fuzz::WriteFile(path, data + 1, size - 1);
  surge::TriangleMesh mesh;
  try {
    mesh = surge::ReadTriangleMesh(path);
  } catch (const std::runtime_error& e) {
    if (std::string(e.what()).find(path) == std::string::npos)
      surge::fuzz::Finding(std::string("mesh error without the file name: ") + e.what());
    return 0;
  } catch (const std::exception& e) {
    surge::fuzz::Finding(std::string("mesh reader threw another type: ") + e.what());
  }
  const int nv = int(mesh.vertices.size());
  if (mesh.part.size() != mesh.triangles.size()) surge::fuzz::Finding("part per triangle");
  for (const surge::Vec3& v : mesh.vertices)
    if (!v.allFinite()) surge::fuzz::Finding("a non-finite vertex was accepted");
  for (const auto& t : mesh.triangles)
    for (int i : t)
      if (i < 0 || i >= nv) surge::fuzz::Finding("triangle index out of range");
  for (int p : mesh.part)
    if (p < 0 || p >= int(mesh.part_names.size())) surge::fuzz::Finding("part index out of range");
  const surge::Aabb box = surge::BoundingBox(mesh);
  const bool closed = surge::CountOpenEdges(mesh) == 0;
  const surge::Vec3 centre = 0.5 * (box.min + box.max);
  if (closed && mesh.triangles.size() < 20000) (void)surge::InsideMesh(mesh, centre);
  try {
    surge::MeshDistanceField field(mesh, !closed);
    (void)field.Query(centre, 1e300);
    (void)field.Query(box.max + (box.max - box.min), 1e300);
  } catch (const std::invalid_argument&) {
    // degenerate triangles: the builder turns this into a SceneError at the mesh's key
  }
  return 0;
}

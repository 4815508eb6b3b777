// Triangle meshes: reading CAD files (STL, OBJ, PLY, glTF via assimp, in mesh_reader.cpp) and
// geometric queries on closed meshes (mesh_query.cpp). Only our own types appear here (STYLE H.10).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "core/math.h"

namespace surge {

struct TriangleMesh {
  std::vector<Vec3> vertices;                // [m] (after any scaling by the caller)
  std::vector<std::array<int, 3>> triangles; // indices into `vertices`, counter-clockwise outward
  // Mesh parts (CAD objects/groups), so that forces on a mesh obstacle can be grouped by part.
  // Either empty (the whole mesh is one part) or one entry per triangle: an index into part_names.
  std::vector<int> part;
  std::vector<std::string> part_names;  // unique names; "part<k>" where the file has none
};

struct Aabb {
  Vec3 min = Vec3::Zero();  // [m]
  Vec3 max = Vec3::Zero();  // [m]
};

// Reads every triangle of every mesh in `path` (STL ascii/binary, OBJ, PLY, glTF, ... whatever
// assimp recognises), with node transforms applied and identical vertices merged. Each named
// assimp mesh (OBJ `o`/`g` group, glTF mesh, STL solid) becomes a part; meshes with the same name
// share one part, unnamed ones are called "part<k>" (k = the part's index). part/part_names are
// always filled.
// Throws std::runtime_error naming the file if it is not a regular file, cannot be read, holds
// no triangles, a non-finite vertex or a face index out of range.
TriangleMesh ReadTriangleMesh(const std::string& path);

// Axis-aligned bounding box of the vertices. Pre: the mesh has at least one vertex.
Aabb BoundingBox(const TriangleMesh& mesh);

// Number of edges not shared by exactly two triangles (0 for a closed, manifold mesh).
int CountOpenEdges(const TriangleMesh& mesh);

// True if `p` lies inside the closed mesh: ray-parity (even-odd) test along several fixed, generic
// directions; rays that graze an edge or vertex are discarded and the rest vote (majority).
// Points within about 1e-10 * (bounding-box diagonal) of the surface may go either way.
// Cost: O(triangles) per call. Pre: the mesh is closed (CountOpenEdges == 0).
bool InsideMesh(const TriangleMesh& mesh, const Vec3& p);

}  // namespace surge

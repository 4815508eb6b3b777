// Signed distance to a triangle mesh for the node contact (issue #5): FCL BVH (OBBRSS) for the
// nearest triangle, sign from angle-weighted pseudo-normals (Baerentzen & Aanaes 2005) so that
// non-convex meshes, sharp corners and thin walls get the right side. FCL stays in
// mesh_distance.cpp (pimpl); only our own types appear here.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "mesh/mesh.h"

namespace surge {

struct MeshDistance {
  Real distance = 0;           // signed: < 0 inside the structure [m]
  Vec3 normal = Vec3::UnitX(); // unit outward normal of the surface at the nearest point
  int triangle = -1;           // nearest triangle (index into the mesh), -1 when beyond max_distance
};

class MeshDistanceField {
 public:
  // Builds the BVH. A closed mesh (CountOpenEdges == 0) has an inside; with `one_sided` an open
  // mesh (a terrain patch, a single wall) is allowed and the side its triangle normals point to
  // is outside. Throws std::invalid_argument with a clear message for an empty mesh, degenerate
  // (zero-area) triangles, or an open mesh without `one_sided`.
  MeshDistanceField(TriangleMesh mesh, bool one_sided);
  ~MeshDistanceField();
  MeshDistanceField(const MeshDistanceField&) = delete;
  MeshDistanceField& operator=(const MeshDistanceField&) = delete;

  // Signed distance, outward normal and nearest triangle for point x. The normal is
  // (x - c) / |x - c| signed to point outward (c = closest surface point), which is the face
  // normal when c is inside a face, and the feature's pseudo-normal when x is on the surface.
  // When x is farther than max_distance (> 0) from the surface the result is
  // {+max_distance, UnitX, -1} whatever the side: the search is pruned there and the sign is not
  // resolved (callers only act on distance <= 0 + small band; pass infinity for the full field).
  // Thread-safe: const, no shared scratch.
  MeshDistance Query(const Vec3& x, Real max_distance) const;

  const TriangleMesh& mesh() const;
  Aabb bounds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surge

// Geometric queries on triangle meshes: bounding box, closedness, point-in-mesh (ray parity).
#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "mesh/mesh.h"

namespace surge {
namespace {

enum class RayHit { kMiss, kHit, kDegenerate };

// Moller & Trumbore (1997) ray-triangle intersection of the ray p + t d, t > 0.
// kDegenerate when the ray passes within `edge_tol` (barycentric) of an edge or vertex, or when
// `p` lies (within `t_tol`) on the triangle's plane inside it: the parity count is then unreliable.
RayHit IntersectRay(const Vec3& p, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                    Real edge_tol, Real t_tol) {
  const Vec3 e1 = b - a;
  const Vec3 e2 = c - a;
  const Vec3 h = d.cross(e2);
  const Real det = e1.dot(h);
  const Real scale = e1.norm() * e2.norm();
  if (std::abs(det) <= 1e-12 * scale) return RayHit::kMiss;  // ray parallel to the plane
  const Real inv = 1.0 / det;
  const Vec3 s = p - a;
  const Real u = inv * s.dot(h);
  if (u < -edge_tol || u > 1 + edge_tol) return RayHit::kMiss;
  const Vec3 q = s.cross(e1);
  const Real v = inv * d.dot(q);
  if (v < -edge_tol || u + v > 1 + edge_tol) return RayHit::kMiss;
  const Real t = inv * e2.dot(q);
  if (t < -t_tol) return RayHit::kMiss;
  if (t <= t_tol) return RayHit::kDegenerate;
  if (u <= edge_tol || v <= edge_tol || u + v >= 1 - edge_tol) return RayHit::kDegenerate;
  return RayHit::kHit;
}

}  // namespace

Aabb BoundingBox(const TriangleMesh& mesh) {
  Aabb box{mesh.vertices.front(), mesh.vertices.front()};
  for (const Vec3& v : mesh.vertices) {
    box.min = box.min.cwiseMin(v);
    box.max = box.max.cwiseMax(v);
  }
  return box;
}

int CountOpenEdges(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int i = t[k];
      const int j = t[(k + 1) % 3];
      ++uses[{std::min(i, j), std::max(i, j)}];
    }
  }
  int open = 0;
  for (const auto& [edge, count] : uses) open += count != 2 ? 1 : 0;
  return open;
}

bool InsideMesh(const TriangleMesh& mesh, const Vec3& p) {
  // Fixed directions with irrational-looking components, so that rays from lattice points
  // (half-integer multiples of a spacing) rarely meet the edges of axis-aligned CAD geometry.
  static const Vec3 kDirections[] = {
      Vec3(0.5773, 0.5811, 0.5735).normalized(),  Vec3(-0.7071, 0.3162, 0.6325).normalized(),
      Vec3(0.2673, -0.8018, 0.5345).normalized(), Vec3(-0.4082, -0.4472, -0.7960).normalized(),
      Vec3(0.8165, 0.1925, -0.5443).normalized(), Vec3(-0.1231, 0.9847, -0.1231).normalized(),
      Vec3(0.3015, -0.3015, -0.9045).normalized()};
  constexpr int kVotesNeeded = 3;  // stop after this many non-degenerate rays (odd: no ties)
  const Aabb box = BoundingBox(mesh);
  if ((p.array() < box.min.array()).any() || (p.array() > box.max.array()).any()) return false;
  const Real t_tol = 1e-10 * (box.max - box.min).norm();
  constexpr Real kEdgeTol = 1e-9;

  int inside_votes = 0;
  int valid = 0;
  for (const Vec3& d : kDirections) {
    int crossings = 0;
    bool degenerate = false;
    for (const auto& t : mesh.triangles) {
      const RayHit hit = IntersectRay(p, d, mesh.vertices[t[0]], mesh.vertices[t[1]],
                                      mesh.vertices[t[2]], kEdgeTol, t_tol);
      if (hit == RayHit::kDegenerate) {
        degenerate = true;
        break;
      }
      crossings += hit == RayHit::kHit ? 1 : 0;
    }
    if (degenerate) continue;
    ++valid;
    inside_votes += crossings % 2;
    if (valid == kVotesNeeded) break;
  }
  return 2 * inside_votes > valid;
}

}  // namespace surge

// Domain walls as node constraints (seed Planar / Fixed nodes, spec seed-algorithms.md §5.3),
// shared by the grid update and the per-body velocity fields (body_contact.cpp).
#pragma once
#include <cmath>

#include "core/model.h"
#include "grid/sparse_grid.h"

namespace surge {

struct WallPlane {
  int axis;
  Real sign;   // +1: inward normal along +axis (a "min" face), -1 along -axis
  Real level;  // wall coordinate [m]
  Wall wall;
  int face;
};

inline int ActiveWalls(const Model& model, WallPlane* out) {
  int count = 0;
  for (int f = 0; f < kFaceCount; ++f) {
    const Wall& w = model.walls[f];
    if (w.kind == WallKind::kOpen) continue;
    const int axis = f / 2;
    if (axis >= model.dim) continue;
    const bool is_min = (f % 2) == 0;
    out[count++] = WallPlane{axis, is_min ? 1.0 : -1.0,
                             is_min ? model.domain_min[axis] : model.domain_max[axis], w, f};
  }
  return count;
}

// Whether the material touches active wall k in the node column of `node` (MarkWallContacts);
// true when the gap test is off.
inline bool WallTouched(const SparseGrid& grid, int k, const Vec3i& node) {
  const SparseGrid::WallTouch& t = grid.wall_touch[k];
  if (t.touched.empty()) return true;
  const int i1 = node[(t.axis + 1) % 3] - t.lo[(t.axis + 1) % 3];
  const int i2 = node[(t.axis + 2) % 3] - t.lo[(t.axis + 2) % 3];
  return i1 >= 0 && i1 < t.n1 && i2 >= 0 && i2 < t.n2 && t.touched[size_t(i1) * t.n2 + i2];
}

// Constrains node velocity v (node `node`, at position xn) by every wall the node lies on or
// beyond and the material touches there (WallTouched on `grid`; null: every wall), in face order. Slip: v.n >= 0 (separable) or v.n = 0; no-slip: v = 0 (seed Fixed); friction:
// Coulomb limit |dv_t| <= mu |dv_n| on the tangential velocity (Bardenhagen et al. 2000,
// eq. (11)). dv[k] receives the velocity change made by wall k. Returns true when any wall acted.
inline bool ApplyWalls(const WallPlane* walls, int count, const Vec3& xn, Real tolerance, Vec3& v,
                       Vec3* dv, const SparseGrid* grid = nullptr, const Vec3i& node = Vec3i::Zero()) {
  bool acted = false;
  for (int k = 0; k < count; ++k) {
    const WallPlane& w = walls[k];
    dv[k].setZero();
    if (w.sign * (xn[w.axis] - w.level) > tolerance) continue;  // node inside the domain
    if (grid && !WallTouched(*grid, k, node)) continue;  // the material has not reached it here
    acted = true;
    const Vec3 before = v;
    if (w.wall.kind == WallKind::kNoSlip) {
      v.setZero();
    } else {
      const Real vn = w.sign * v[w.axis];  // velocity along the inward normal
      if (vn < 0 || !w.wall.separable) {   // separable walls release tension (vn >= 0)
        v[w.axis] -= w.sign * vn;          // remove the normal component
        if (w.wall.kind == WallKind::kFriction) {
          Vec3 vt = v;
          vt[w.axis] = 0;
          const Real vt_norm = vt.norm();
          const Real limit = w.wall.friction * std::abs(vn);
          v -= vt_norm <= limit ? vt : Vec3((limit / vt_norm) * vt);  // stick : slip
        }
      }
    }
    dv[k] = v - before;
  }
  return acted;
}


}  // namespace surge

// Domain walls as node constraints (seed Planar / Fixed nodes, spec seed-algorithms.md §5.3),
// shared by the grid update and the per-body velocity fields (body_contact.cpp).
#pragma once
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

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

// The gap test's marking (docs/walls.md "Stand-off"): a particle touches wall k when its
// distance d to the plane is at most 1.5 of its half-size V0^(1/dim) / 2, tested without the
// root (a cbrt was about 1 % of a step): d <= 0, or d^dim <= 0.75^dim V0. It then marks the node
// columns along the wall that its kernel reaches. The constructor sizes and clears
// grid.wall_touch (serial; the maps are small); MarkTouched may run on any thread: a mark is a
// relaxed store of 1, so the maps are the same set for any thread count and particle order.
// RebuildGrid marks in its pass over the particles (no pass of its own, no broad phase): a
// particle that Near::MayTouch lets through goes to MarkTouched.
class WallTouchMarker {
 public:
  WallTouchMarker(const Model& model, Real dx, SparseGrid& grid);
  // Whether there is anything to mark: the gap test is on and a wall is active.
  bool active() const { return count_ > 0; }
  // The node ranges recently marked per wall (by one thread's run of particles), kCache of them
  // direct-mapped on the range's first node: neighbouring particles mostly mark the same columns,
  // which are then skipped. One entry per wall kept only 40 % of the marks away on a spreading
  // water column, whose 2 x 2 particles per cell across a wall give 4 ranges taken in turn.
  struct Recent {
    static constexpr int kCache = 8;
    int range[kFaceCount][kCache][4];
    Recent() {
      for (auto& w : range)
        for (auto& r : w) r[0] = r[1] = r[2] = r[3] = std::numeric_limits<int>::min();
    }
  };
  // The nearest-wall reject: most particles touch no wall, and are rejected on their distance
  // to the nearest one, without a loop (d^dim is monotone in d, so no wall passes the test when
  // the nearest fails it). A value type, so that a particle loop can keep it in registers.
  struct Near {
    Real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // the active walls' levels per axis; -inf / +inf
    Real c_touch = 0;                          // where there is none
    bool cube = true;                          // 3-D: d^3
    bool MayTouch(const Vec3& x, Real volume0) const {
      const Real d = std::min(std::min(std::min(x.x() - lo[0], hi[0] - x.x()),
                                       std::min(x.y() - lo[1], hi[1] - x.y())),
                              std::min(x.z() - lo[2], hi[2] - x.z()));
      return !(d > 0 && (cube ? d * d * d : d * d) > c_touch * volume0);
    }
  };
  const Near& near() const { return near_; }
  // Tests x against every wall and marks the columns of those it touches. Inline, so that the
  // request pass's AVX build (RebuildGrid) takes its floors and ceilings in one instruction each:
  // as a call into the portable build the marking was 70 of a 1e4-particle water column's 110 us
  // request pass.
  [[gnu::always_inline]] inline void MarkTouched(const Vec3& x, Real volume0,
                                                 Recent& recent) const;

 private:
  [[gnu::always_inline]] inline void MarkColumns(const Vec3& x, Real volume0, int k,
                                                 int (*recent)[4]) const;
  WallPlane walls_[kFaceCount];
  Near near_;
  int count_ = 0;
  int dim_ = 3;
  Real reach_ = 0;  // kernel reach along the wall [m]: where the stencil has non-zero weights
  Real inv_dx_ = 0;
  bool gimp_ = false;
  SparseGrid* grid_ = nullptr;
};

inline void WallTouchMarker::MarkTouched(const Vec3& x, Real volume0, Recent& recent) const {
  for (int k = 0; k < count_; ++k) {
    const WallPlane& w = walls_[k];
    const Real d = w.sign * (x[w.axis] - w.level);
    if (d <= 0 || (dim_ == 3 ? d * d * d : d * d) <= near_.c_touch * volume0)
      MarkColumns(x, volume0, k, recent.range[k]);
  }
}

inline void WallTouchMarker::MarkColumns(const Vec3& x, Real volume0, int k,
                                         int (*recent)[4]) const {
  SparseGrid::WallTouch& t = grid_->wall_touch[k];
  // GIMP: the particle's half width adds to the reach (only there: the root is not free).
  const Real r = !gimp_ ? reach_
                        : reach_ + 0.5 * (dim_ == 3 ? std::cbrt(volume0) : std::sqrt(volume0));
  int range[4];  // node index range along the two tangential axes: first, last, first, last
  for (int j = 1; j <= 2; ++j) {
    const int a = (t.axis + j) % 3;
    int* span = range + 2 * (j - 1);
    if (a >= dim_) {
      span[0] = span[1] = 0;
      continue;
    }
    // nodes with |x_i - x_p| < r (a weight exactly at the edge of the support is zero)
    span[0] = int(std::floor((x[a] - r) * inv_dx_)) + 1;
    span[1] = int(std::ceil((x[a] + r) * inv_dx_)) - 1;
  }
  int* seen = recent[unsigned(range[0] * 3 + range[2]) % unsigned(Recent::kCache)];
  if (range[0] == seen[0] && range[1] == seen[1] && range[2] == seen[2] && range[3] == seen[3])
    return;  // marked just before
  for (int i = 0; i < 4; ++i) seen[i] = range[i];
  const int a1 = (t.axis + 1) % 3, a2 = (t.axis + 2) % 3;
  const int i1_end = std::min(range[1] - t.lo[a1], t.n1 - 1);
  const int i2_end = std::min(range[3] - t.lo[a2], t.n2 - 1);
  for (int i1 = std::max(range[0] - t.lo[a1], 0); i1 <= i1_end; ++i1)
    for (int i2 = std::max(range[2] - t.lo[a2], 0); i2 <= i2_end; ++i2)
      if (std::atomic_ref<uint8_t> mark(t.touched[size_t(i1) * t.n2 + i2]);
          mark.load(std::memory_order_relaxed) == 0)  // a line both threads mark stays shared
        mark.store(1, std::memory_order_relaxed);
}

// Whether the material touches active wall k in the node column of `node` (WallTouchMarker);
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

// Grid solve and domain walls (Mast 2013 eqs. (2.13)-(2.14); spec seed-algorithms.md §5.3).
// Walls act on v_{n+1}; the FLIP increment dv = v_{n+1} - v_n then carries the constraint to
// the particles (the [REC] variant of spec §1.3), and the reaction is the momentum removed:
// R = -m_i (v_c - v_u) / dt, summed per face.
#include <cmath>

#include "core/parallel.h"
#include "transfer/transfer.h"

namespace surge {
namespace {

struct WallPlane {
  int axis;
  Real sign;   // +1: inward normal along +axis (a "min" face), -1 along -axis
  Real level;  // wall coordinate [m]
  Wall wall;
  int face;
};

int ActiveWalls(const Model& model, WallPlane* out) {
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

// Constrains node velocity v (node at position xn) by every wall the node lies on or beyond,
// in face order. Slip: v.n >= 0 (separable) or v.n = 0; no-slip: v = 0 (seed Fixed); friction:
// Coulomb limit |dv_t| <= mu |dv_n| on the tangential velocity (Bardenhagen et al. 2000,
// eq. (11)). dv[k] receives the velocity change made by wall k. Returns true when any wall acted.
inline bool ApplyWalls(const WallPlane* walls, int count, const Vec3& xn, Real tolerance, Vec3& v,
                       Vec3* dv) {
  bool acted = false;
  for (int k = 0; k < count; ++k) {
    const WallPlane& w = walls[k];
    dv[k].setZero();
    if (w.sign * (xn[w.axis] - w.level) > tolerance) continue;  // node inside the domain
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

}  // namespace

void UpdateGridVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid,
                        WallReport& report) {
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, robust to round-off of i*dx
  const size_t nb = grid.block_count();
  // Per-block partial reactions, summed in block order afterwards (deterministic).
  std::vector<std::array<Real, 19>>& partial = grid.wall_partials;  // 6 faces x 3 + work
  partial.assign(nb, {});
  ParallelFor(nb, 4, [&](size_t b) {
    auto& part = partial[b];
    for (int l = 0; l < kBlockNodes; ++l) {
      const size_t i = b * kBlockNodes + l;
      const Real m = grid.mass[i];
      if (m <= 0) {
        grid.velocity[i].setZero();
        grid.velocity_new[i].setZero();
        continue;
      }
      const Vec3 v = grid.momentum[i] / m;                        // (2.13)
      const Vec3 vu = v + ctx.dt * (grid.force[i] / m + ctx.gravity);  // (2.13)-(2.14)
      grid.velocity[i] = v;
      Vec3 vc = vu;
      if (wall_count > 0) {
        const Vec3i node = grid.block_origin[b] + Vec3i(l / 64, (l / 8) % 8, l % 8);
        Vec3 dv[kFaceCount];
        if (ApplyWalls(walls, wall_count, node.cast<Real>() * ctx.dx, tolerance, vc, dv)) {
          // Reaction on each wall: R = -m dv / dt (spec §5.3).
          for (int k = 0; k < wall_count; ++k)
            for (int d = 0; d < 3; ++d) part[3 * walls[k].face + d] -= m * dv[k][d] / ctx.dt;
          // Work of the wall force on the material at the constrained velocity: zero for
          // fixed and frictionless walls, negative for sliding friction.
          part[18] += m * (vc - vu).dot(vc);
        }
      }
      grid.velocity_new[i] = vc;
    }
  });
  report = WallReport{};
  for (size_t b = 0; b < nb; ++b) {
    for (int f = 0; f < kFaceCount; ++f)
      report.force[f] += Vec3(partial[b][3 * f], partial[b][3 * f + 1], partial[b][3 * f + 2]);
    report.work += partial[b][18];
  }
}

void ApplyRemappedVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid) {
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, robust to round-off of i*dx
  ParallelFor(grid.block_count(), 4, [&](size_t b) {
    for (int l = 0; l < kBlockNodes; ++l) {
      const size_t i = b * kBlockNodes + l;
      const Real m = grid.mass[i];
      if (m <= 0) continue;
      Vec3 v = grid.momentum[i] / m;
      if (wall_count > 0) {
        const Vec3i node = grid.block_origin[b] + Vec3i(l / 64, (l / 8) % 8, l % 8);
        Vec3 dv[kFaceCount];
        ApplyWalls(walls, wall_count, node.cast<Real>() * ctx.dx, tolerance, v, dv);
      }
      grid.velocity_new[i] = v;
    }
  });
}

}  // namespace surge

// Grid solve and domain walls (Mast 2013 eqs. (2.13)-(2.14); spec seed-algorithms.md §5.3).
// Walls act on v_{n+1}; the FLIP increment dv = v_{n+1} - v_n then carries the constraint to
// the particles (the [REC] variant of spec §1.3), and the reaction is the momentum removed:
// R = -m_i (v_c - v_u) / dt, summed per face.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/parallel.h"
#include "transfer/owned_loops.h"
#include "transfer/transfer.h"
#include "transfer/walls.h"

namespace surge {

// Per-block partial sums of the walls: per face force (3), torque about the origin (3) and
// nodes with mass (1), then the work, the largest nodal reaction and the highest node.
constexpr int kFaceSums = 7;
constexpr int kWork = kFaceSums * kFaceCount, kMaxNodal = kWork + 1, kMaxElevation = kWork + 2;
static_assert(kMaxElevation + 1 == std::tuple_size_v<SparseGrid::WallPartial>);

WallTouchMarker::WallTouchMarker(const Model& model, Real dx, SparseGrid& grid)
    : dim_(model.dim), inv_dx_(1.0 / dx), gimp_(model.shape == ShapeFunction::kGimp), grid_(&grid) {
  for (auto& t : grid.wall_touch) t.touched.clear();
  if (!model.wall_gap_test) return;
  count_ = ActiveWalls(model, walls_);
  for (int a = 0; a < 3; ++a) {
    near_.lo[a] = -std::numeric_limits<Real>::infinity();
    near_.hi[a] = std::numeric_limits<Real>::infinity();
  }
  for (int k = 0; k < count_; ++k)
    (walls_[k].sign > 0 ? near_.lo : near_.hi)[walls_[k].axis] = walls_[k].level;
  near_.c_touch = model.dim == 3 ? 0.421875 : 0.5625;  // 0.75^dim
  near_.cube = dim_ == 3;
  reach_ = dx * (model.shape == ShapeFunction::kLinear             ? 1.0
                 : model.shape == ShapeFunction::kQuadraticBspline ? 1.5
                 : model.shape == ShapeFunction::kCubicBspline     ? 2.0
                                                                   : 1.0);
  for (int k = 0; k < count_; ++k) {
    SparseGrid::WallTouch& t = grid.wall_touch[k];
    t.axis = walls_[k].axis;
    for (int j = 1; j <= 2; ++j) {
      const int a = (t.axis + j) % 3;
      const bool used = a < model.dim;
      // node columns over the domain plus 3 cells either side (stencils reach past it)
      const int lo = used ? int(std::floor(model.domain_min[a] * inv_dx_)) - 3 : 0;
      const int hi = used ? int(std::ceil(model.domain_max[a] * inv_dx_)) + 3 : 0;
      t.lo[a] = lo;
      (j == 1 ? t.n1 : t.n2) = hi - lo + 1;
    }
    t.touched.assign(size_t(t.n1) * size_t(t.n2), 0);
  }
}


void UpdateGridVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid,
                        WallReport& report) {
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, robust to round-off of i*dx
  const Real g = model.gravity.norm();
  const Vec3 up = g > 0 ? Vec3(-model.gravity / g) : Vec3::UnitY();
  const bool keep_reaction = !model.sensors.empty();  // SparseGrid::reaction: sensors only
  const size_t nb = grid.block_count();
  // Per-block partial reactions, summed in block order afterwards (deterministic).
  std::vector<SparseGrid::WallPartial>& partial = grid.wall_partials;
  partial.assign(nb, {});
  ForOwnedBlocks(grid, [&](size_t b) {
    auto& part = partial[b];
    part[kMaxElevation] = -std::numeric_limits<Real>::infinity();
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = b * size_t(grid.block_nodes) + size_t(l);
      const Real m = grid.mass[i];
      if (m <= 0) {
        grid.momentum[i].setZero();  // v_{i,n}: momentum's buffer becomes `velocity` below
        grid.velocity_new[i].setZero();
        if (keep_reaction) grid.reaction[i].setZero();
        continue;
      }
      const Vec3 v = grid.momentum[i] / m;                        // (2.13)
      const Vec3 vu = v + ctx.dt * (grid.force[i] / m + ctx.gravity);  // (2.13)-(2.14)
      grid.momentum[i] = v;  // in place: p_i is not read again (SparseGrid::momentum)
      Vec3 vc = vu;
      if (wall_count > 0) {
        const Vec3i node = grid.block_origin[b] + grid.LocalCoord(l);
        const Vec3 x = node.cast<Real>() * ctx.dx;
        Vec3 dv[kFaceCount];
        if (ApplyWalls(walls, wall_count, x, tolerance, vc, dv, &grid, node)) {
          // Reaction on each wall: R = -m dv / dt (spec §5.3), its moment, its node count.
          for (int k = 0; k < wall_count; ++k) {
            const Real depth = walls[k].sign * (x[walls[k].axis] - walls[k].level);
            if (depth > tolerance || !WallTouched(grid, k, node)) continue;  // did not act here
            Real* f = &part[kFaceSums * walls[k].face];
            const Vec3 r = -m * dv[k] / ctx.dt;
            const Vec3 tq = x.cross(r);
            for (int d = 0; d < 3; ++d) {
              f[d] += r[d];
              f[3 + d] += tq[d];
            }
            f[6] += depth >= -tolerance ? 1 : 0;  // area: the nodes on the plane only
          }
          part[kMaxNodal] = std::max(part[kMaxNodal], m * (vc - vu).norm() / ctx.dt);
          part[kMaxElevation] = std::max(part[kMaxElevation], up.dot(x));
          // Work of the wall force on the material at the constrained velocity: zero for
          // fixed and frictionless walls, negative for sliding friction.
          part[kWork] += m * (vc - vu).dot(vc);
        }
      }
      grid.velocity_new[i] = vc;
      if (keep_reaction) grid.reaction[i] = m * (vu - vc) / ctx.dt;  // walls' share; 0 elsewhere
    }
  });
  // The buffer now holds v_{i,n}: it becomes `velocity`, and `momentum` takes velocity's old
  // buffer (empty but in MUSL, whose re-map fills it; BuildTopology swaps them back).
  grid.velocity.swap(grid.momentum);
  report = WallReport{};
  report.max_elevation = -std::numeric_limits<Real>::infinity();
  for (size_t b = 0; b < nb; ++b) {
    for (int f = 0; f < kFaceCount; ++f) {
      const Real* p = &partial[b][kFaceSums * f];
      report.force[f] += Vec3(p[0], p[1], p[2]);
      report.torque[f] += Vec3(p[3], p[4], p[5]);
      report.contact_nodes[f] += int64_t(p[6]);
    }
    report.work += partial[b][kWork];
    report.max_nodal_force = std::max(report.max_nodal_force, partial[b][kMaxNodal]);
    report.max_elevation = std::max(report.max_elevation, partial[b][kMaxElevation]);
  }
}

void MirrorGhostNodes(const Model& model, const StepContext& ctx, SparseGrid& grid, bool collect,
                      WallReport* report) {
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, as in UpdateGridVelocity
  auto node_coord = [&](size_t i) { return grid.NodeCoord(i); };  // node index of grid node i
  if (collect) {
    grid.ghosts.clear();
    for (size_t b = 0; b < grid.block_count(); ++b) {
      const Vec3i origin = grid.block_origin[b];
      for (int k = 0; k < wall_count; ++k) {
        const WallPlane& w = walls[k];
        const int a = w.axis;
        const int outer = w.sign > 0 ? origin[a] : origin[a] + kBlockDim - 1;  // farthest out
        if (w.sign * (outer * ctx.dx - w.level) >= -tolerance) continue;       // none beyond
        // Mirror image of node index n across the plane: 2 level / dx - n (exact for a wall on
        // a node or half-way between two; else the nearest node, docs/walls.md).
        const int twice = int(std::lround(2 * w.level * ctx.inv_dx));
        for (int l = 0; l < grid.block_nodes; ++l) {
          const size_t i = b * size_t(grid.block_nodes) + size_t(l);
          if (!(grid.mass[i] > 0)) continue;
          const Vec3i n = node_coord(i);
          if (w.sign * (n[a] * ctx.dx - w.level) >= -tolerance) continue;  // on or inside
          Vec3i mirror = n;
          mirror[a] = twice - n[a];
          grid.ghosts.push_back({uint32_t(i), k, mirror});
        }
      }
    }
    const size_t n = grid.ghosts.size();
    grid.ghost_mirror_block.resize(2 * n);
    grid.ghost_mirror_index.resize(2 * n);
    // arithmetic shift = floor division (C++20), as in RebuildGrid
    auto block_of = [](const Vec3i& c) {
      return Vec3i(c.x() >> kBlockBits, c.y() >> kBlockBits, c.z() >> kBlockBits);
    };
    for (size_t g = 0; g < n; ++g) {
      const SparseGrid::GhostNode& gh = grid.ghosts[g];
      const int a = walls[gh.wall].axis;
      Vec3i plane = gh.mirror;  // the node on the wall plane between ghost and mirror
      plane[a] = int(std::lround(walls[gh.wall].level * ctx.inv_dx));
      grid.ghost_mirror_block[2 * g] = block_of(gh.mirror);
      grid.ghost_mirror_block[2 * g + 1] = block_of(plane);
    }
    LookupBlocks(grid, grid.ghost_mirror_block.data(), 2 * n, grid.ghost_mirror_index.data());
  }
  auto node_index = [&](size_t k, const Vec3i& c) -> int64_t {  // -1: not active or no mass
    const int32_t b = grid.ghost_mirror_index[k];
    if (b < 0) return -1;
    const Vec3i local = c - grid.ghost_mirror_block[k] * kBlockDim;
    const size_t j = size_t(b) * size_t(grid.block_nodes) + size_t(grid.Local(local.x(), local.y(), local.z()));
    return grid.mass[j] > 0 ? int64_t(j) : -1;
  };
  const bool keep_reaction = report && !model.sensors.empty();
  const bool fold = model.ghost_nodes == GhostNodes::kMirror || model.ghost_nodes == GhostNodes::kFoldAll;
  const bool fold_separable = model.ghost_nodes == GhostNodes::kFoldAll;
  // The walls' extra reaction, work and sensor share for a velocity change at node i from
  // `before` to its current v_{n+1} (spec §5.3: the momentum the constraint removes). The sensor
  // share goes to node `sensor_node`: the ghost for the mirror's share too, so that a force
  // sensor at the wall (a box reaching past it) holds the whole reaction of its wall columns.
  auto credit = [&](const WallPlane& w, size_t i, const Vec3i& c, const Vec3& before,
                    size_t sensor_node) {
    const Vec3& v = grid.velocity_new[i];
    const Real m = grid.mass[i];
    const Vec3 vu = grid.velocity[i] + ctx.dt * (grid.force[i] / m + ctx.gravity);
    const Vec3 r = -m * (v - before) / ctx.dt;
    const Vec3 x = c.cast<Real>() * ctx.dx;
    report->force[w.face] += r;
    report->torque[w.face] += x.cross(r);
    report->work += m * ((v - vu).dot(v) - (before - vu).dot(before));
    report->max_nodal_force = std::max(report->max_nodal_force, m * (v - vu).norm() / ctx.dt);
    if (keep_reaction) grid.reaction[sensor_node] += r;
  };
  // Serial, in block order: a ghost reads its mirror inside the domain along its wall's axis and
  // writes only the ghost and that mirror, so the result does not depend on the thread count.
  for (size_t g = 0; g < grid.ghosts.size(); ++g) {
    const SparseGrid::GhostNode& gh = grid.ghosts[g];
    const WallPlane& w = walls[gh.wall];
    const int a = w.axis;
    const Vec3i ghost = node_coord(gh.node);
    if (!WallTouched(grid, gh.wall, ghost)) continue;  // not touched here: the ghost stays free
    const int64_t j = node_index(2 * g, gh.mirror);
    const Real u = j >= 0 ? grid.velocity_new[size_t(j)][a] : 0;  // the mirror's v_{n+1} along a
    if (w.wall.separable && w.wall.kind != WallKind::kNoSlip) {
      // Separable wall: mirror only where the material presses on the wall, i.e. where the
      // wall removed an inflow at the node on the plane below (its free prediction moves out
      // of the domain); elsewhere the material may leave and the ghost keeps v.n >= 0. With no
      // node on the plane (a wall half-way between nodes) the mirror's own motion decides.
      Vec3i plane = gh.mirror;
      plane[a] = int(std::lround(w.level * ctx.inv_dx));
      const bool on_plane = std::abs(plane[a] * ctx.dx - w.level) <= tolerance;
      bool pressing = w.sign * u < 0;
      if (on_plane) {
        const int64_t k = node_index(2 * g + 1, plane);
        pressing = k >= 0 && w.sign * (grid.velocity[size_t(k)][a] +
                                       ctx.dt * (grid.force[size_t(k)][a] / grid.mass[size_t(k)] +
                                                 ctx.gravity[a])) < 0;
      }
      if (!pressing) continue;
    }
    const size_t i = gh.node;
    Vec3& v = grid.velocity_new[i];
    const Vec3 before = v;
    // A mirror node on or beyond another wall keeps that wall's constraint: no fold there.
    // Only bilateral walls fold (no-slip, and slip with `separable: false`, e.g. a symmetry
    // plane): on a separable or frictional wall the fold would move part of the normal reaction
    // off the wall's nodes, where the contact switch and the Coulomb limit act (measured: a block
    // on a mu = 0.3 floor slid 11 % fast), so there the normal velocity is mirrored only.
    // `fold_all` folds at separable slip walls too (here the material presses on it).
    const bool bilateral = w.wall.kind == WallKind::kNoSlip ||
                           (w.wall.kind == WallKind::kSlip && (!w.wall.separable || fold_separable));
    bool mirror_free = fold && bilateral && j >= 0;
    for (int kk = 0; mirror_free && kk < wall_count; ++kk)
      mirror_free = kk == gh.wall ||
                    walls[kk].sign * (gh.mirror[walls[kk].axis] * ctx.dx - walls[kk].level) > tolerance;
    if (!mirror_free) {
      v[a] = -u;  // odd extension of the normal velocity across the plane
      if (report) credit(w, i, ghost, before, i);
      continue;
    }
    // Folded mirror (`mirror`): with the ghost slaved to its mirror node k, v_g = S v_k (S = -1
    // on the normal component; on every component for a no-slip wall), the Galerkin basis of
    // node k is N_k + S N_g, so its lumped mass is m_k + m_g and its momentum m_k v_k + S m_g v_g
    // (the reflection method for a Dirichlet condition on a symmetric B-spline basis; without it
    // the ghost's share of the internal force is lost and a clamped elastic bar converges at
    // first order, docs/walls.md). v_g is the ghost's own unconstrained velocity: its free
    // prediction (2.13)-(2.14) in the grid update, its re-mapped velocity in the MUSL re-map.
    const size_t k = size_t(j);
    const Real mg = grid.mass[i], mk = grid.mass[k];
    const Vec3 vg = collect ? Vec3(grid.velocity[i] + ctx.dt * (grid.force[i] / mg + ctx.gravity))
                            : Vec3(ctx.mass_scale * grid.momentum[i] / mg);
    Vec3& vk = grid.velocity_new[k];
    const Vec3 before_k = vk;
    const bool all = w.wall.kind == WallKind::kNoSlip;
    for (int d = 0; d < 3; ++d) {
      if (d != a && !all) continue;  // tangential components of slip and friction walls: own
      vk[d] = (mk * vk[d] - mg * vg[d]) / (mk + mg);
      v[d] = -vk[d];
    }
    if (!report) continue;
    credit(w, i, ghost, before, i);
    credit(w, k, gh.mirror, before_k, i);
  }
}

// Cundall's local damping (Anura3D manual §6.3.1): m a = f + f_damp (6.22), f_damp = -alpha |f|
// v/|v| per degree of freedom (6.23), f = f_ext - f_int the unbalanced nodal force (gravity and
// tractions included), v = v_n the nodal velocity at the start of the step (a component at rest
// is not damped; with alpha < 1 the damping never reverses f). Only the components that no
// constraint changed are damped: where a wall or an obstacle set v_{n+1} (v_{n+1,d} differs from
// the free prediction v_n + dt (f/m + g)), the degree of freedom is prescribed, as a fixity is
// in the manual, and its reaction (logged by the wall or obstacle) stays the undamped one.
namespace {
// kBalance: also sum the force balance of (6.29) per block (only the equilibrium rule reads it).
template <bool kBalance>
void DampNodes(const StepContext& ctx, SparseGrid& grid, DampingBalance* balance) {
  const Real alpha = ctx.damping;
  ForOwnedBlocks(grid, [&](size_t b) {
    [[maybe_unused]] Real unbalanced = 0, external = 0;
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = b * size_t(grid.block_nodes) + size_t(l);
      const Real m = grid.mass[i];
      if (m <= 0) continue;
      const Vec3& v = grid.velocity[i];
      const Vec3 a = grid.force[i] / m + ctx.gravity;  // f/m
      const Vec3 vu = v + ctx.dt * (grid.force[i] / m + ctx.gravity);  // as UpdateGridVelocity
      Vec3& vn = grid.velocity_new[i];
      if constexpr (kBalance) external += (m * ctx.gravity).squaredNorm();  // ||F_ext||^2 (6.29)
      for (int d = 0; d < 3; ++d) {
        if (vn[d] != vu[d]) continue;  // constrained by a wall or an obstacle
        if constexpr (kBalance) unbalanced += (m * a[d]) * (m * a[d]);  // ||F_ext - F_int||^2
        const Real sign = v[d] > 0 ? 1 : (v[d] < 0 ? -1 : 0);
        vn[d] = v[d] + ctx.dt * (a[d] - alpha * std::abs(a[d]) * sign);  // (6.22)-(6.23)
      }
    }
    if constexpr (kBalance) {
      balance->partials[2 * b] = unbalanced;
      balance->partials[2 * b + 1] = external;
    }
  });
}
}  // namespace

void ApplyLocalDamping(const StepContext& ctx, SparseGrid& grid, DampingBalance* balance) {
  if (!balance) return DampNodes<false>(ctx, grid, nullptr);
  balance->partials.assign(2 * grid.block_count(), 0.0);
  DampNodes<true>(ctx, grid, balance);
  balance->unbalanced = balance->external = 0;
  for (size_t b = 0; b < grid.block_count(); ++b) {  // block order: thread-count independent
    balance->unbalanced += balance->partials[2 * b];
    balance->external += balance->partials[2 * b + 1];
  }
}

void ApplyRemappedVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid) {
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, robust to round-off of i*dx
  ForOwnedBlocks(grid, [&](size_t b) {
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = b * size_t(grid.block_nodes) + size_t(l);
      const Real m = grid.mass[i];
      if (m <= 0) continue;
      // The re-mapped momentum is sum N m_p v_p; with mass scaling the nodal mass is beta m_i
      // (ParticleToGridStage), so the velocity takes the same factor.
      Vec3 v = ctx.mass_scale * grid.momentum[i] / m;
      if (wall_count > 0) {
        const Vec3i node = grid.block_origin[b] + grid.LocalCoord(l);
        Vec3 dv[kFaceCount];
        ApplyWalls(walls, wall_count, node.cast<Real>() * ctx.dx, tolerance, v, dv, &grid, node);
      }
      grid.velocity_new[i] = v;
    }
  });
  if (model.ghost_nodes != GhostNodes::kConstrain && wall_count > 0) MirrorGhostNodes(model, ctx, grid, false, nullptr);
}

}  // namespace surge

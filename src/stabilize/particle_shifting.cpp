// Particle shifting by the delta-correction (particle_shifting.h). Scatter as in
// particle_to_grid.cpp (colour phases, padded block buffers, fixed summation order), gather by
// particle runs as in grid_to_particle.cpp; every sum has an order that does not depend on the
// thread count.
#include "stabilize/particle_shifting.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/parallel.h"
#include "transfer/owned_loops.h"
#include "transfer/stencil_loop.h"

namespace surge {
namespace {

using K = QuadraticBsplineKernel;

// Whether particle p belongs to a material that shifts (the groups are few: a linear scan).
bool Shifts(const Model& model, const std::vector<MaterialGroup>& groups, size_t p) {
  for (const MaterialGroup& g : groups)
    if (p >= g.begin && p < g.end) return model.materials[size_t(g.material)].particle_shifting;
  return false;
}

// V~_i = sum_p N_ip J_p V0_p of one block's particles into its padded buffer, then into the
// grid slots (particle order, then colour order).
template <int kDim>
void ScatterVolume(const StepContext& ctx, const Particles& P, const SparseGrid& grid, size_t blk,
                   std::vector<Real>& buf, std::vector<Real>& volume) {
  using Pad = BlockPad<kDim, K>;
  buf.assign(Pad::kSize, 0.0);
  const Vec3i origin = grid.block_origin[blk];
  if (grid.block_begin[blk] == grid.block_begin[blk + 1]) return;
  for (uint32_t k = grid.block_begin[blk]; k < grid.block_begin[blk + 1]; ++k) {
    const uint32_t p = grid.sorted[k];
    const Real v = DetOfDim<kDim>(P.F[p]) * P.volume0[p];  // V_p = J_p V0_p
    Stencil<kDim, K> st;
    st.Compute(P.x[p], ctx.inv_dx, 0);
    const Vec3i lb = st.base - origin;
    for (int i = 0; i < st.W; ++i)
      for (int j = 0; j < st.W; ++j) {
        const Real wv = st.w[0][i] * st.w[1][j] * v;
        Real* row = &buf[size_t(Pad::Index(lb.x() + i, lb.y() + j, lb.z()))];
        for (int c = 0; c < st.Wz; ++c) row[c] += st.w[2][c] * wv;
      }
  }
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const Real v = buf[size_t(Pad::Index(a, b, c))];
        if (v == 0) continue;
        const long g = PaddedToGrid(grid, blk, a, b, c);
        SURGE_ASSERT(g >= 0);
        if (g >= 0) volume[size_t(g)] += v;
      }
}

// g_p = 2 V_p sum_i E_i grad N_ip for the shifting particles of one run (0 for the others).
template <int kDim>
void GatherGradient(const Model& model, const StepContext& ctx,
                    const std::vector<MaterialGroup>& groups, const Particles& P,
                    const SparseGrid& grid, const SparseGrid::ParticleRun& run,
                    const std::vector<Real>& excess, std::vector<Vec3>& shift) {
  using Pad = BlockPad<kDim, K>;
  const size_t blk = run.block;
  const Vec3i origin = grid.block_origin[blk];
  // The block's padded excesses, copied once per run (one neighbour lookup per node instead of
  // one per particle and stencil node: the same values, so the same sums). A node of no active
  // block reads 0, as a node without excess: no particle's stencil holds one.
  thread_local std::vector<Real> halo;
  halo.resize(Pad::kSize);
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const long g = PaddedToGrid(grid, blk, a, b, c);
        halo[size_t(Pad::Index(a, b, c))] = g < 0 ? 0.0 : excess[size_t(g)];
      }
  for (uint32_t k = run.begin; k < run.end; ++k) {
    const uint32_t p = grid.sorted[k];
    shift[p].setZero();
    if (!Shifts(model, groups, p)) continue;
    Stencil<kDim, K> st;
    st.Compute(P.x[p], ctx.inv_dx, 0);
    const Vec3i lb = st.base - origin;
    Vec3 grad = Vec3::Zero();
    for (int i = 0; i < st.W; ++i)
      for (int j = 0; j < st.W; ++j) {
        const Real* row = &halo[size_t(Pad::Index(lb.x() + i, lb.y() + j, lb.z()))];
        for (int c = 0; c < st.Wz; ++c) {
          const Real e = row[c];
          if (e != 0) grad += e * st.Gradient(i, j, c);
        }
      }
    shift[p] = 2 * DetOfDim<kDim>(P.F[p]) * P.volume0[p] * grad;  // g_p
  }
}

template <int kDim>
void Compute(const Model& model, const StepContext& ctx, const std::vector<MaterialGroup>& groups,
             const Particles& P, const SparseGrid& grid, ShiftingScratch& s) {
  const size_t slots = grid.block_count() * size_t(grid.block_nodes);
  s.excess.assign(slots, 0.0);
  for (int colour = 0; colour < 8; ++colour) {
    const auto& blocks = grid.colour[colour];
    ParallelFor(blocks.size(), 1, [&](size_t i) {
      thread_local std::vector<Real> buf;
      ScatterVolume<kDim>(ctx, P, grid, size_t(blocks[i]), buf, s.excess);
    });
  }
  // E_i = max(0, V~_i - V_i), and sum E^2 per block, added in block order.
  s.partial.assign(grid.block_count(), 0.0);
  const int nz = kDim == 3 ? kBlockDim : 1;
  ForOwnedBlocks(grid, [&](size_t blk) {
    const Vec3i origin = grid.block_origin[blk];
    Real sum = 0;
    for (int a = 0; a < kBlockDim; ++a)
      for (int b = 0; b < kBlockDim; ++b)
        for (int c = 0; c < nz; ++c) {
          Real& e = s.excess[blk * size_t(grid.block_nodes) + size_t(grid.Local(a, b, c))];
          if (e == 0) continue;
          // Excesses below 1e-9 of the node's volume are round-off (a regular lattice maps its
          // volume exactly up to it) and are not shifted.
          const Real v = NodeVolume(model, origin + Vec3i(a, b, c), s.poses);
          e = e - v > 1e-9 * v ? e - v : 0;
          sum += e * e;
        }
    s.partial[blk] = sum;
  });
  Real excess_sq = 0;
  for (Real v : s.partial) excess_sq += v;
  s.excess_sq = excess_sq;
  s.shift.resize(P.size());
  ForOwnedRuns(grid, [&](size_t r) {
    GatherGradient<kDim>(model, ctx, groups, P, grid, grid.runs[r], s.excess, s.shift);
  });
  // sum |g_p|^2 in fixed particle chunks (the runs depend on the thread count).
  s.partial.assign(kReductionChunks, 0.0);
  ParallelChunks(P.size(), [&](size_t c, size_t begin, size_t end) {
    Real sum = 0;
    for (size_t p = begin; p < end; ++p) sum += s.shift[p].squaredNorm();
    s.partial[c] = sum;
  });
  Real grad_sq = 0;
  for (Real v : s.partial) grad_sq += v;
  const Real b0 = grad_sq > 0 ? excess_sq / grad_sq : 0;  // Newton step on sum E^2
  ParallelForStatic(P.size(), [&](size_t p) { s.shift[p] *= -b0; });
}

}  // namespace

bool AnyParticleShifting(const Model& model) {
  return std::any_of(model.materials.begin(), model.materials.end(),
                     [](const Material& m) { return m.particle_shifting; });
}

Real QuadraticBsplineTail(Real a) {
  // 1 - F(a), F the integral of N from -1.5: N = (1.5 + xi)^2 / 2 on [-1.5, -0.5],
  // 3/4 - xi^2 on [-0.5, 0.5], (1.5 - xi)^2 / 2 on [0.5, 1.5].
  if (a <= -1.5) return 1;
  if (a >= 1.5) return 0;
  if (a <= -0.5) return 1 - (1.5 + a) * (1.5 + a) * (1.5 + a) / 6;
  if (a >= 0.5) return (1.5 - a) * (1.5 - a) * (1.5 - a) / 6;
  return 0.5 - 0.75 * a + a * a * a / 3;  // 1/6 + [3/4 xi - xi^3/3] from a to 1/2
}

Real NodeShareOutside(Real a) {
  const Real exact = 1 - QuadraticBsplineTail(a);           // the B-spline's integral, xi < a
  const Real tributary = std::clamp<Real>(0.5 + a, 0, 1);  // the cell [-1/2, 1/2], xi < a
  // A regular particle lattice (n per cell) maps exactly h per node away from a wall (the
  // B-spline's Fourier transform vanishes at the lattice's harmonics). Next to a wall on a node
  // plane, with n = 2, it maps 1/2 at the wall node (both shares 1/2), 31/32 at the node inside
  // (exact 46/48, tributary 1) and 1/64 at the ghost node beyond (exact 1/48, tributary 0).
  // The larger of the two shares is the target, so that a regular lattice is never shifted.
  return std::max(exact, tributary);
}

Real NodeVolume(const Model& model, const Vec3i& node, const std::vector<ObstaclePose>& poses) {
  Real v = 1;
  Vec3 x = Vec3::Zero();  // node position [m]
  for (int d = 0; d < model.dim; ++d) {
    x[d] = node[d] * model.dx;
    Real share = 1;
    if (model.walls[size_t(2 * d)].kind != WallKind::kOpen)
      share *= NodeShareOutside((x[d] - model.domain_min[d]) / model.dx);
    if (model.walls[size_t(2 * d + 1)].kind != WallKind::kOpen)
      share *= NodeShareOutside((model.domain_max[d] - x[d]) / model.dx);
    v *= share * model.dx;
  }
  for (size_t o = 0; o < poses.size(); ++o) {
    const Real band = 2 * model.dx;  // the support reaches 1.5 h
    const SurfaceQuery q = QueryObstacle(model.obstacles[o], poses[o], x, model.dim, 0, band);
    if (q.distance < band) v *= NodeShareOutside(q.distance / model.dx);
  }
  return v;  // 2-D: per 1 m thickness, as V0
}

void ComputeParticleShift(const Model& model, const StepContext& ctx,
                          const std::vector<MaterialGroup>& groups, const Particles& particles,
                          const std::vector<RigidBodyState>& rigid, const SparseGrid& grid,
                          ShiftingScratch& scratch) {
  SURGE_CHECK(model.shape == ShapeFunction::kQuadraticBspline,
              "particle shifting needs the quadratic B-spline");
  scratch.poses.clear();
  for (const Obstacle& o : model.obstacles) scratch.poses.push_back(PoseAt(o, ctx.time, &rigid));
  if (model.dim == 3)
    Compute<3>(model, ctx, groups, particles, grid, scratch);
  else
    Compute<2>(model, ctx, groups, particles, grid, scratch);
}

void ApplyParticleShift(const Model& model, Particles& particles, const ShiftingScratch& scratch) {
  SURGE_CHECK(scratch.shift.size() == particles.size(), "particle shift of every particle");
  ParallelForStatic(particles.size(), [&](size_t p) {
    const Vec3 x = particles.x[p] + scratch.shift[p];
    for (int d = 0; d < model.dim; ++d)
      if (!(x[d] > model.domain_min[d] && x[d] < model.domain_max[d])) return;
    particles.x[p] = x;
  });
}

}  // namespace surge

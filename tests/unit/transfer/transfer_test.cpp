// P2G / G2P conservation (Drake-style transfer tests): mass and linear momentum to round-off for
// every kernel and transfer; APIC also angular momentum; node sums independent of threads.
#include "transfer/transfer.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <algorithm>

#include "core/parallel.h"
#include "core/simd.h"
#include "support/test_state.h"
#include "transfer/owned_loops.h"
#include "transfer/walls.h"

namespace surge {
namespace {

struct Totals {
  Real mass = 0;
  Vec3 momentum = Vec3::Zero();
  Vec3 angular = Vec3::Zero();
};

Totals GridTotals(const SparseGrid& g, Real dx) {
  Totals t;
  for (size_t b = 0; b < g.block_count(); ++b)
    for (int l = 0; l < g.block_nodes; ++l) {
      const size_t i = b * size_t(g.block_nodes) + size_t(l);
      t.mass += g.mass[i];
      t.momentum += g.momentum[i];
      const Vec3 x = g.NodeCoord(i).cast<Real>() * dx;
      t.angular += x.cross(g.momentum[i]);
    }
  return t;
}

StepContext Context(const Model& m) {
  StepContext c;
  c.dt = 0;  // positions stay put, so a second P2G sees the same stencils
  c.dx = m.dx;
  c.inv_dx = 1.0 / m.dx;
  return c;
}

class TransferTest
    : public ::testing::TestWithParam<std::tuple<ShapeFunction, TransferScheme, int>> {};

TEST_P(TransferTest, ConservesMassAndMomentum) {
  const auto [shape, transfer, dim] = GetParam();
  Model m = testing::SmallModel(dim, shape, transfer, 0.1);
  // Far from the origin and across block boundaries (negative coordinates too).
  State s = testing::RandomState(dim, 3000, Vec3(-3.21, 1.7, dim == 3 ? 0.4 : 0.0), 1.3, m.dx);
  if (transfer != TransferScheme::kApic)
    for (auto& C : s.particles.C) C.setZero();
  const StepContext ctx = Context(m);
  SparseGrid grid;
  RebuildGrid(m, s.particles, grid);
  ParticleToGrid(m, ctx, s.particles, grid);

  Totals p;
  for (size_t i = 0; i < s.particles.size(); ++i) {
    p.mass += s.particles.mass[i];
    p.momentum += s.particles.mass[i] * s.particles.v[i];
  }
  const Totals g1 = GridTotals(grid, m.dx);
  const Real scale = p.mass;  // |v| <= 1, so momentum sums are O(mass)
  EXPECT_NEAR(g1.mass, p.mass, 1e-13 * scale);
  EXPECT_LT((g1.momentum - p.momentum).norm(), 1e-13 * scale);

  // G2P then P2G again: linear (and for APIC angular) momentum of the grid is unchanged.
  WallReport walls;
  UpdateGridVelocity(m, ctx, grid, walls);
  std::vector<Mat3> L;
  GridToParticle(m, ctx, grid, s.particles, &L, nullptr);
  SparseGrid grid2;
  RebuildGrid(m, s.particles, grid2);
  ParticleToGrid(m, ctx, s.particles, grid2);
  const Totals g2 = GridTotals(grid2, m.dx);
  EXPECT_LT((g2.momentum - g1.momentum).norm(), 1e-12 * scale);
  if (transfer == TransferScheme::kApic) {
    const Real lscale = scale * 5.0;  // |x| <= ~5 m
    EXPECT_LT((g2.angular - g1.angular).norm(), 1e-12 * lscale)
        << "APIC must conserve angular momentum";
  }
}

INSTANTIATE_TEST_SUITE_P(
    All, TransferTest,
    ::testing::Combine(::testing::Values(ShapeFunction::kLinear, ShapeFunction::kGimp,
                                         ShapeFunction::kQuadraticBspline,
                                         ShapeFunction::kCubicBspline),
                       ::testing::Values(TransferScheme::kFlip, TransferScheme::kPicFlip,
                                         TransferScheme::kApic),
                       ::testing::Values(2, 3)));

// BinParticles' stable counting sort, serial (many blocks for the particles) and in chunks (at
// most n / 256 blocks): every block's particles in index order, the blocks in block order, and
// the same arrays for 1, 2 and 3 threads.
TEST(TransferTest, BinningIsAStableSortByBlockForAnyThreadCount) {
  for (const auto& [count, cell] : {std::pair{size_t(3000), 0.1}, std::pair{size_t(60000), 0.25}}) {
    const size_t n = count;  // a plain variable: lambdas may not capture structured bindings (C++17)
    const Real dx = cell;
    const Model m = testing::SmallModel(3, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, dx);
    const State s = testing::RandomState(3, n, Vec3(-0.4, 0.3, 0.2), 1.3, m.dx);
    std::vector<uint32_t> sorted[3], begin[3];
    for (int t = 0; t < 3; ++t) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, t + 1);
      tbb::task_arena arena(t + 1);
      arena.execute([&] {
        SparseGrid grid;
        RebuildGrid(m, s.particles, grid);
        const size_t nb = grid.block_count();
        const bool chunked = kReductionChunks * nb <= n / 4;
        EXPECT_EQ(chunked, n > 10000) << "n = " << n << ", " << nb << " blocks";
        ASSERT_EQ(grid.block_begin.size(), nb + 1);
        ASSERT_EQ(grid.block_begin[nb], n);
        for (size_t b = 0; b < nb; ++b)
          for (uint32_t k = grid.block_begin[b]; k < grid.block_begin[b + 1]; ++k) {
            ASSERT_EQ(size_t(grid.particle_block[grid.sorted[k]]), b);
            if (k > grid.block_begin[b]) {
              ASSERT_LT(grid.sorted[k - 1], grid.sorted[k]);
            }
          }
        sorted[t] = grid.sorted;
        begin[t] = grid.block_begin;
      });
    }
    EXPECT_EQ(sorted[1], sorted[0]);
    EXPECT_EQ(sorted[2], sorted[0]);
    EXPECT_EQ(begin[1], begin[0]);
  }
}

// P2G on 1 thread (colour phases) and on 2, 3 and 4 (OrderedBlockScatter: each thread its own
// blocks; 3 and 4 threads oversubscribe this 2-core machine) gives bitwise the same grid, in 2-D
// and 3-D and with the MUSL re-map's momentum-only scatter. Both of OrderedBlockScatter's
// schedules are covered: a ball of radius 1.5 m has more blocks with particles than its
// two-phase limit for any of these thread counts in 3-D (ordered adds per target block, threads
// waiting on and taking over each other's blocks), one of 0.25 m fewer (two phases).
TEST(TransferTest, ParticleToGridIsBitwiseIndependentOfThreadCount) {
  for (const auto& [dim, radius] : {std::pair{2, 1.5}, std::pair{3, 1.5}, std::pair{3, 0.25}}) {
    Model m = testing::SmallModel(dim, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.05);
    State s = testing::RandomState(dim, 20000, Vec3(0.3, 0.2, 0.1), radius, m.dx);
    {
      SparseGrid grid;
      RebuildGrid(m, s.particles, grid);
      size_t used = 0;
      for (size_t b = 0; b < grid.block_count(); ++b)
        used += grid.block_begin[b + 1] > grid.block_begin[b] ? 1 : 0;
      if (dim == 3 && radius > 1) {
        ASSERT_GT(used, 4 * kTwoPhaseBlocksPerThread);
      } else if (dim == 3) {
        ASSERT_LE(used, 2 * kTwoPhaseBlocksPerThread);
      }
    }
    for (auto& S : s.particles.stress) S = Mat3::Random();
    const StepContext ctx = Context(m);
    std::vector<Real> mass[4];
    std::vector<Vec3> force[4], momentum[4];
    for (int t = 0; t < 4; ++t) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, t + 1);
      tbb::task_arena arena(t + 1);
      arena.execute([&] {
        ASSERT_EQ(WorkerThreads(), size_t(t + 1));
        SparseGrid grid;
        RebuildGrid(m, s.particles, grid);
        ParticleToGrid(m, ctx, s.particles, grid);
        mass[t] = grid.mass;
        force[t] = grid.force;
        RemapMomentum(m, ctx, s.particles, grid);
        momentum[t] = grid.momentum;
      });
    }
    for (int t = 1; t < 4; ++t) {
      ASSERT_EQ(mass[0].size(), mass[t].size());
      EXPECT_TRUE(mass[0] == mass[t]) << dim << "-D, r = " << radius << ", " << t + 1 << " threads";
      EXPECT_TRUE(force[0] == force[t]) << dim << "-D, r = " << radius << ", " << t + 1 << " threads";
      EXPECT_TRUE(momentum[0] == momentum[t]) << dim << "-D, r = " << radius << ", " << t + 1 << " threads";
    }
  }
}


// BuildTopology keeps the OpenVDB tree's internal nodes from step to step and deletes only the
// leaves no longer needed (clearing the tree once many have been deleted): a grid rebuilt after
// other particle sets, with the column moved 0.67 m (5 blocks) in 20 sets, has the same blocks,
// numbering, neighbours, colours and binning as a grid built fresh for the same particles.
// Each set of particles is binned three times: as made, moved by a hundredth of a cell (mostly
// the same blocks: the leaf set is compared), and once more unmoved (the same requests: the
// tables are kept).
TEST(TransferTest, RebuiltTopologyEqualsAFreshOne) {
  Model m = testing::SmallModel(3, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.02);
  SparseGrid reused;
  for (int k = 0; k < 60; ++k) {
    const int c = k / 3;
    State s = testing::RandomState(3, 3000, Vec3(0.3 + 0.035 * c, 0.2, -0.1 * (c % 3)),
                                   0.3 + 0.01 * (c % 5), m.dx, unsigned(c + 1));
    if (k % 3 != 0)
      for (Vec3& x : s.particles.x) x += Vec3(0.01, -0.01, 0.01) * m.dx;
    RebuildGrid(m, s.particles, reused);
    SparseGrid fresh;
    RebuildGrid(m, s.particles, fresh);
    ASSERT_EQ(reused.block_count(), fresh.block_count()) << "step " << k;
    EXPECT_TRUE(reused.block_origin == fresh.block_origin) << "step " << k;
    EXPECT_TRUE(reused.neighbor == fresh.neighbor) << "step " << k;
    EXPECT_TRUE(reused.colour == fresh.colour) << "step " << k;
    EXPECT_TRUE(reused.block_begin == fresh.block_begin) << "step " << k;
    EXPECT_TRUE(reused.sorted == fresh.sorted) << "step " << k;
    EXPECT_TRUE(reused.mass == fresh.mass) << "step " << k;  // zeroed
  }
}

// The walls' gap test (RebuildGrid) marks the node column of every particle that touches a wall
// (d <= 0 or d <= 0.75 V0^(1/dim)), also for particles deep inside, in blocks far from every
// wall, whose volumes are large enough to touch; and with the gap test off it leaves no map.
TEST(TransferTest, WallContactsMarkEveryTouchingParticlesColumn) {
  for (int dim = 2; dim <= 3; ++dim) {
    Model m = testing::SmallModel(dim, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.1);
    m.domain_min = Vec3(-3, -3, dim == 3 ? -3 : 0);
    m.domain_max = Vec3(3, 3, dim == 3 ? 3 : 0);
    for (int f = 0; f < 2 * dim; ++f) m.walls[size_t(f)].kind = WallKind::kSlip;
    State s = testing::RandomState(dim, 4000, Vec3::Zero(), 5.9, m.dx);
    Particles& P = s.particles;
    // Deep inside, in blocks a metre and more from every wall: 0.75 V0^(1/dim) = 3.15 m > the
    // 2.6-3 m to the nearest wall.
    for (size_t p = 0; p < 4; ++p) {
      P.x[p] = Vec3(0.4 - 0.1 * Real(p), 0.05 * Real(p), 0.0);
      P.volume0[p] = std::pow(4.2, dim);
    }
    SparseGrid grid;
    RebuildGrid(m, P, grid);
    WallPlane walls[kFaceCount];
    const int count = ActiveWalls(m, walls);
    ASSERT_EQ(count, 2 * dim);
    int touching = 0;
    for (size_t p = 0; p < P.size(); ++p)
      for (int k = 0; k < count; ++k) {
        const Real d = walls[k].sign * (P.x[p][walls[k].axis] - walls[k].level);
        if (d > 0.75 * std::pow(P.volume0[p], 1.0 / dim)) continue;
        ++touching;
        Vec3i node;
        for (int a = 0; a < 3; ++a) node[a] = int(std::lround(P.x[p][a] / m.dx));
        EXPECT_TRUE(WallTouched(grid, k, node)) << "dim " << dim << " particle " << p << " wall " << k;
      }
    EXPECT_GE(touching, 4 * dim) << "dim " << dim;  // the deep ones touch every wall
    m.wall_gap_test = false;
    RebuildGrid(m, P, grid);
    for (int k = 0; k < count; ++k) EXPECT_TRUE(grid.wall_touch[size_t(k)].touched.empty()) << k;
  }
}

// The gathers' work items (SparseGrid::runs) cover every binned particle once, in block order,
// without empty runs; a crowded block is cut so that no run exceeds the cap, the same way for 1
// and 2 threads (the fused stress update sums its power per run); and G2P's result does not
// depend on the cut (pass 2: one run per block).
TEST(TransferTest, GatherRunsCoverEveryParticleAndGridToParticleIgnoresTheCut) {
  Model m = testing::SmallModel(3, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.05);
  const State start = testing::RandomState(3, 20000, Vec3(0.3, 0.2, 0.1), 0.4, m.dx);
  const StepContext ctx = Context(m);
  std::vector<Vec3> v[3], x[3];
  std::vector<Mat3> C[3];
  std::vector<SparseGrid::ParticleRun> runs[2];
  size_t blocks_used = 0;  // blocks with particles
  for (int t = 0; t < 3; ++t) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, t == 1 ? 2 : 1);
    State s = start;
    SparseGrid grid;
    RebuildGrid(m, s.particles, grid);
    const size_t n = s.particles.size();
    size_t next = 0, largest = 0;
    for (const SparseGrid::ParticleRun& r : grid.runs) {
      ASSERT_EQ(r.begin, next);
      ASSERT_LT(r.begin, r.end);
      ASSERT_GE(r.begin, grid.block_begin[r.block]);
      ASSERT_LE(r.end, grid.block_begin[r.block + 1]);
      largest = std::max<size_t>(largest, r.end - r.begin);
      next = r.end;
    }
    EXPECT_EQ(next, n);
    EXPECT_LE(largest, std::max<size_t>(256, n / 16 + 1));  // crowded blocks are cut
    blocks_used = 0;
    for (size_t b = 0; b < grid.block_count(); ++b)
      blocks_used += grid.block_begin[b + 1] > grid.block_begin[b];
    if (t < 2) {
      runs[t] = grid.runs;
    } else {  // uncut: one run per block with particles
      grid.runs.clear();
      for (size_t b = 0; b < grid.block_count(); ++b)
        if (grid.block_begin[b + 1] > grid.block_begin[b])
          grid.runs.push_back({uint32_t(b), grid.block_begin[b], grid.block_begin[b + 1]});
    }
    ParticleToGrid(m, ctx, s.particles, grid);
    WallReport walls;
    UpdateGridVelocity(m, ctx, grid, walls);
    GridToParticle(m, ctx, grid, s.particles, nullptr, nullptr);
    v[t] = s.particles.v;
    x[t] = s.particles.x;
    C[t] = s.particles.C;
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  for (size_t r = 0; r < runs[0].size(); ++r) {
    EXPECT_EQ(runs[0][r].block, runs[1][r].block);
    EXPECT_EQ(runs[0][r].begin, runs[1][r].begin);
    EXPECT_EQ(runs[0][r].end, runs[1][r].end);
  }
  EXPECT_GT(runs[0].size(), blocks_used);  // some crowded blocks are cut
  for (int t : {1, 2}) {
    EXPECT_TRUE(v[0] == v[t]) << t;
    EXPECT_TRUE(x[0] == x[t]) << t;
    EXPECT_TRUE(C[0] == C[t]) << t;
  }
}

// Deferred advection (step.h, DeferredAdvection): APIC G2P that leaves x_n, then AdvectParticles,
// gives G2P's own x_{n+1} bitwise, and the same v_p and C_p; the grid's v_{i,n} buffer is the
// momentum's (SparseGrid::momentum), so P2G of the moved particles into the same grid finds it
// again.
TEST(TransferTest, DeferredAdvectionMatchesGridToParticleBitwise) {
  for (int dim : {2, 3}) {
    Model m = testing::SmallModel(dim, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.05);
    const State start =
        testing::RandomState(dim, 5000, Vec3(0.3, 0.2, dim == 3 ? 0.1 : 0.0), 0.6, m.dx);
    StepContext ctx = Context(m);
    ctx.dt = 1e-3;
    ctx.gravity = Vec3(0, -9.81, 0);
    State s[2] = {start, start};
    SparseGrid grid;
    for (int pass = 0; pass < 2; ++pass) {  // pass 1 reuses the grid's swapped buffers
      for (int k = 0; k < 2; ++k) {
        RebuildGrid(m, s[k].particles, grid);
        EXPECT_TRUE(grid.velocity.empty());  // its buffer went back to momentum
        ParticleToGrid(m, ctx, s[k].particles, grid);
        WallReport walls;
        UpdateGridVelocity(m, ctx, grid, walls);
        EXPECT_TRUE(grid.momentum.empty());  // p_i's buffer now holds v_{i,n}
        EXPECT_EQ(grid.velocity.size(), grid.mass.size());
        std::vector<Mat3> L;
        if (k == 0) {
          GridToParticle(m, ctx, grid, s[k].particles, &L, nullptr);
        } else {
          const std::vector<Vec3> x_n = s[k].particles.x;
          GridToParticle(m, ctx, grid, s[k].particles, &L, nullptr, nullptr, /*advect=*/false);
          EXPECT_TRUE(s[k].particles.x == x_n);
          AdvectParticles(ctx, s[k].particles);
        }
      }
      SCOPED_TRACE(::testing::Message() << dim << "-D, pass " << pass);
      EXPECT_TRUE(s[0].particles.x == s[1].particles.x);
      EXPECT_TRUE(s[0].particles.v == s[1].particles.v);
      EXPECT_TRUE(s[0].particles.C == s[1].particles.C);
      EXPECT_FALSE(s[1].particles.x == start.particles.x);  // they moved
    }
  }
}

// The wide (AVX) builds of P2G and G2P (core/simd.h) give bitwise the portable builds' node sums,
// MUSL re-map, velocities, affine matrices, gradients and positions, for every kernel, transfer
// and dimension. Skipped on a CPU without AVX, where only the portable builds run.
TEST(TransferTest, WideKernelsMatchThePortableOnesBitwise) {
  const bool was = SetWideSimd(true);
  if (!WideSimd()) GTEST_SKIP() << "no AVX on this CPU";
  for (int dim : {2, 3})
    for (ShapeFunction shape : {ShapeFunction::kLinear, ShapeFunction::kQuadraticBspline,
                                ShapeFunction::kCubicBspline, ShapeFunction::kGimp})
      for (TransferScheme transfer : {TransferScheme::kApic, TransferScheme::kFlip}) {
        Model m = testing::SmallModel(dim, shape, transfer, 0.05);
        State start =
            testing::RandomState(dim, 3000, Vec3(0.3, 0.2, dim == 3 ? 0.1 : 0.0), 0.5, m.dx);
        for (auto& S : start.particles.stress) S = Mat3::Random();
        for (auto& C : start.particles.C) C = Mat3::Random();
        StepContext ctx = Context(m);
        ctx.dt = 1e-3;
        ctx.gravity = Vec3(0, -9.81, 0);
        State s[2] = {start, start};
        SparseGrid grid[2];
        std::vector<Mat3> L[2];
        std::vector<Vec3> force[2], remapped[2];
        for (int k = 0; k < 2; ++k) {
          SetWideSimd(k == 1);
          ASSERT_EQ(WideSimd(), k == 1);
          RebuildGrid(m, s[k].particles, grid[k]);
          ParticleToGrid(m, ctx, s[k].particles, grid[k]);
          force[k] = grid[k].force;
          WallReport walls;
          UpdateGridVelocity(m, ctx, grid[k], walls);
          GridToParticle(m, ctx, grid[k], s[k].particles, &L[k], nullptr);
          RemapMomentum(m, ctx, s[k].particles, grid[k]);  // MUSL: momentum only
          remapped[k] = grid[k].momentum;
        }
        SCOPED_TRACE(::testing::Message() << dim << "-D, shape " << int(shape) << ", transfer "
                                          << int(transfer));
        EXPECT_TRUE(grid[0].mass == grid[1].mass);
        EXPECT_TRUE(force[0] == force[1]);
        EXPECT_TRUE(grid[0].velocity_new == grid[1].velocity_new);
        EXPECT_TRUE(remapped[0] == remapped[1]);
        EXPECT_TRUE(L[0] == L[1]);
        EXPECT_TRUE(s[0].particles.v == s[1].particles.v);
        EXPECT_TRUE(s[0].particles.C == s[1].particles.C);
        EXPECT_TRUE(s[0].particles.x == s[1].particles.x);
        EXPECT_FALSE(s[0].particles.v == start.particles.v);  // the step changed them
      }
  SetWideSimd(was);
}

}  // namespace
}  // namespace surge

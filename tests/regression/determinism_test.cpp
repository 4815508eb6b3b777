// Determinism (DESIGN §5): the same scene gives bitwise the same state for any thread count.
// Hashes x, v, F, stress and the internal work (FNV-1a over the raw bytes) after a number of steps of the
// flagship scene (contact with the floor, friction, APIC) and of the MUSL two-disk scene.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "core/simd.h"
#include "support/run_scene.h"

namespace surge {
namespace {

uint64_t Fnv1a(uint64_t h, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

uint64_t HashState(const State& s) {
  uint64_t h = 1469598103934665603ull;
  const Particles& P = s.particles;
  h = Fnv1a(h, P.x.data(), P.x.size() * sizeof(Vec3));
  h = Fnv1a(h, P.v.data(), P.v.size() * sizeof(Vec3));
  h = Fnv1a(h, P.F.data(), P.F.size() * sizeof(Mat3));
  h = Fnv1a(h, P.stress.data(), P.stress.size() * sizeof(P.stress[0]));
  h = Fnv1a(h, P.elastic_b.data(), P.elastic_b.size() * sizeof(P.elastic_b[0]));
  h = Fnv1a(h, P.history.data(), P.history.size() * sizeof(P.history[0]));
  h = Fnv1a(h, &s.time, sizeof s.time);
  // The energy record's stress work, summed per G2P run when the stress update is fused into G2P.
  h = Fnv1a(h, &s.internal_work, sizeof s.internal_work);
  return h;
}

uint64_t RunWithThreads(const std::string& scene_file, const std::vector<std::string>& overrides,
                        Real end, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  LoadedScene scene = LoadScene(testing::ScenePath(scene_file), overrides);
  testing::RunUntil(scene, end, [](const State&, const StepReport&) {});
  return HashState(scene.state);
}

TEST(DeterminismTest, FlagshipSceneIsBitwiseIdenticalForOneAndTwoThreads) {
  // The block starts 0.5 m above the floor: by t = 0.45 s it has landed and is sliding.
  const std::vector<std::string> overrides = {"grid.cell_size=0.08"};
  const uint64_t h1 = RunWithThreads("elastic_drop_3d.yaml", overrides, 0.45, 1);
  const uint64_t h2 = RunWithThreads("elastic_drop_3d.yaml", overrides, 0.45, 2);
  EXPECT_EQ(h1, h2);
}

// The AVX builds of the kernels (core/simd.h: P2G, G2P, four spectral decompositions at a time,
// the grid rebuild's requests pass, the anti-locking's block scatters and gathers) against the
// portable ones, end to end: the flagship drop and the column impact's smooth-cap sand with a
// box obstacle (coarse, 0.2 s) under node AS1 (its default), the linear node fit and cell AS2,
// and the 2-D tank drain (linear node fit, folded ghosts), each bitwise the same.
TEST(DeterminismTest, WideKernelsGiveBitwiseThePortableResult) {
  const bool was = SetWideSimd(true);
  if (!WideSimd()) GTEST_SKIP() << "no AVX on this CPU";
  struct Case {
    std::string file;
    std::vector<std::string> overrides;
    Real end;
  };
  const std::string linear_fit = "materials.sand.antilocking={method: node, fit: linear}";
  const std::string cell_as2 =
      "materials.sand.antilocking={method: cell, approach: volumetric_deviatoric}";
  const Case cases[] = {{"elastic_drop_3d.yaml", {"grid.cell_size=0.08"}, 0.45},
                        {"column_impact_3d.yaml", {"parameters.dx=1"}, 0.2},
                        {"column_impact_3d.yaml", {"parameters.dx=1", linear_fit}, 0.2},
                        {"column_impact_3d.yaml", {"parameters.dx=1", cell_as2}, 0.2},
                        {"tank_drain_2d.yaml", {}, 0.1}};
  for (const Case& c : cases) {
    uint64_t h[2];
    for (int wide = 0; wide < 2; ++wide) {
      SetWideSimd(wide == 1);
      h[wide] = RunWithThreads(c.file, c.overrides, c.end, 2);
    }
    EXPECT_EQ(h[0], h[1]) << c.file << (c.overrides.empty() ? "" : " " + c.overrides.back());
  }
  SetWideSimd(was);
}

TEST(DeterminismTest, PlasticSceneIsBitwiseIdenticalForOneAndTwoThreads) {
  // The flagship drop with a J2 block: plastic history must not depend on the thread count.
  const std::vector<std::string> overrides = {
      "grid.cell_size=0.08",
      "materials.rubber={model: j2, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3, "
      "yield_stress: 2.0e3, isotropic_hardening: 1.0e4}"};
  const uint64_t h1 = RunWithThreads("elastic_drop_3d.yaml", overrides, 0.45, 1);
  const uint64_t h2 = RunWithThreads("elastic_drop_3d.yaml", overrides, 0.45, 2);
  EXPECT_EQ(h1, h2);
}

TEST(DeterminismTest, SoilCollapseIsBitwiseIdenticalForOneAndTwoThreads) {
  // The sand column with the modified Drucker-Prager (history: lambda and the evolving angles)
  // and with the Matsuoka-Nakai model (principal Newton); a = 1, to t = 0.06 s (plastic by then).
  for (const std::string model : {"modified_drucker_prager", "matsuoka_nakai_dp"}) {
    const std::vector<std::string> overrides = {"bodies.0.particles_per_cell=2", "parameters.a=1",
                                                "materials.sand.model=" + model};
    const uint64_t h1 = RunWithThreads("column_collapse_2d.yaml", overrides, 0.06, 1);
    const uint64_t h2 = RunWithThreads("column_collapse_2d.yaml", overrides, 0.06, 2);
    EXPECT_EQ(h1, h2) << model;
  }
}

TEST(DeterminismTest, AntiLockedScenesAreBitwiseIdenticalForOneAndTwoThreads) {
  // Water (node-based, the fluid default; USL) and sand (cell-based on the trial elastic
  // strain; MUSL): the anti-locking scatter must keep the fixed summation order.
  const std::vector<std::string> water = {"grid.cell_size=0.0095", "bodies.0.particles_per_cell=2"};
  EXPECT_EQ(RunWithThreads("dam_break_2d.yaml", water, 0.05, 1),
            RunWithThreads("dam_break_2d.yaml", water, 0.05, 2));
  const std::vector<std::string> sand = {"bodies.0.particles_per_cell=2", "parameters.a=1",
                                         "grid.update=musl",
                                         "materials.sand.antilocking={method: cell}"};
  EXPECT_EQ(RunWithThreads("column_collapse_2d.yaml", sand, 0.03, 1),
            RunWithThreads("column_collapse_2d.yaml", sand, 0.03, 2));
  // The full-tensor approaches: hybrid (node trace, cell deviator) and AS3CV on the sand's trial
  // elastic strain, and the stress approximation on top; the moment scatter must keep the fixed
  // order too.
  for (const char* al : {"{method: hybrid}", "{method: cell, approach: constant_volumetric}",
                         "{method: smoothing}", "{method: node, approach: volumetric_deviatoric}",
                         "{method: hybrid, stress: true}",
                         "{method: node, approach: volumetric_deviatoric, stress: true}"}) {
    std::vector<std::string> full = sand;
    full.back() = std::string("materials.sand.antilocking=") + al;
    EXPECT_EQ(RunWithThreads("column_collapse_2d.yaml", full, 0.03, 1),
              RunWithThreads("column_collapse_2d.yaml", full, 0.03, 2))
        << al;
  }
}

TEST(DeterminismTest, DampedAndViscousScenesAreBitwiseIdenticalForOneAndTwoThreads) {
  // Local damping on the grid (switched off at 0.02 s) and the bulk viscosity q, carried across
  // steps by particle id through the reordering every 10 steps (docs/antilocking.md).
  const std::vector<std::string> sand = {"bodies.0.particles_per_cell=2", "parameters.a=1",
                                         "damping={local: 0.7, until: 0.02}",
                                         "materials.sand.bulk_viscosity={quadratic: 1.5, linear: 0.2}"};
  const uint64_t h1 = RunWithThreads("column_collapse_2d.yaml", sand, 0.04, 1);
  EXPECT_EQ(h1, RunWithThreads("column_collapse_2d.yaml", sand, 0.04, 2));
  // Each option changes the run (so both code paths ran).
  EXPECT_NE(h1, RunWithThreads("column_collapse_2d.yaml", {sand[0], sand[1], sand[2]}, 0.04, 2));
  EXPECT_NE(h1, RunWithThreads("column_collapse_2d.yaml", {sand[0], sand[1], sand[3]}, 0.04, 2));
  // The equilibrium rule (Anura3D §6.4): its force and energy sums decide the release step (about
  // 0.39 s in this column), so they must not depend on the thread count either; the release
  // changes the run against damping to the end.
  const std::vector<std::string> eq = {"damping={local: 0.7, equilibrium: {}}"};
  const uint64_t h3 = RunWithThreads("geostatic_column_2d.yaml", eq, 0.5, 1);
  EXPECT_EQ(h3, RunWithThreads("geostatic_column_2d.yaml", eq, 0.5, 2));
  EXPECT_NE(h3, RunWithThreads("geostatic_column_2d.yaml", {"damping={local: 0.7}"}, 0.5, 2));
}

TEST(DeterminismTest, ParticleShiftingIsBitwiseIdenticalForOneAndTwoThreads) {
  // The dam break with barrier (node anti-locking, an obstacle box) with particle shifting
  // through the impact: the excess and gradient sums must keep a fixed order; shifting changes
  // the run.
  const std::vector<std::string> water = {"materials.water.particle_shifting=true"};
  const uint64_t h1 = RunWithThreads("dam_break_barrier_2d.yaml", water, 0.6, 1);
  EXPECT_EQ(h1, RunWithThreads("dam_break_barrier_2d.yaml", water, 0.6, 2));
  EXPECT_NE(h1, RunWithThreads("dam_break_barrier_2d.yaml", {}, 0.6, 2));
}

TEST(DeterminismTest, SettleRecipeIsBitwiseIdenticalForOneAndTwoThreads) {
  // The settle recipe of docs/antilocking.md (the linear node fit with its extrapolation limit,
  // the ghosts folded at the frictionless walls, particle shifting) through the barrier impact.
  const std::vector<std::string> recipe = {
      "materials.water.particle_shifting=true", "domain.ghost_nodes=fold_all",
      "materials.water.antilocking={method: node, fit: linear}"};
  const uint64_t h1 = RunWithThreads("dam_break_barrier_2d.yaml", recipe, 0.6, 1);
  EXPECT_EQ(h1, RunWithThreads("dam_break_barrier_2d.yaml", recipe, 0.6, 2));
  EXPECT_NE(h1, RunWithThreads("dam_break_barrier_2d.yaml", {recipe[0], recipe[1]}, 0.6, 2));
}

TEST(DeterminismTest, MirroredGhostNodesAreBitwiseIdenticalForOneAndTwoThreads) {
  // The 3-D drop (quadratic B-splines, USL) landing on the floor, and the sand column with MUSL
  // (the mirror is applied again to the re-mapped velocity); both with domain.ghost_nodes: mirror.
  const std::vector<std::string> drop = {"grid.cell_size=0.08", "domain.ghost_nodes=mirror"};
  const uint64_t h1 = RunWithThreads("elastic_drop_3d.yaml", drop, 0.45, 1);
  EXPECT_EQ(h1, RunWithThreads("elastic_drop_3d.yaml", drop, 0.45, 2));
  const std::vector<std::string> sand = {"bodies.0.particles_per_cell=2", "parameters.a=1",
                                         "grid.update=musl", "domain.ghost_nodes=mirror"};
  const uint64_t h2 = RunWithThreads("column_collapse_2d.yaml", sand, 0.06, 1);
  EXPECT_EQ(h2, RunWithThreads("column_collapse_2d.yaml", sand, 0.06, 2));
  // The mirror changes the sand run (its ghost nodes have mass from t = 0).
  EXPECT_NE(h2, RunWithThreads("column_collapse_2d.yaml",
                               {sand[0], sand[1], sand[2], "domain.ghost_nodes=constrain"}, 0.06, 2));
}

TEST(DeterminismTest, FoldedGhostNodesAreBitwiseIdenticalForOneAndTwoThreads) {
  // The folded mirror (ghost_nodes: mirror at a bilateral wall): the cantilever clamped by a
  // no-slip wall (every component folded), with USL and with MUSL (folded again on the re-map).
  for (const char* update : {"usl", "musl"}) {
    const std::vector<std::string> beam = {"grid.cell_size=0.25", std::string("grid.update=") + update};
    const uint64_t h1 = RunWithThreads("cantilever_2d.yaml", beam, 0.02, 1);
    EXPECT_EQ(h1, RunWithThreads("cantilever_2d.yaml", beam, 0.02, 2)) << update;
    // The fold changes the run (against the velocity-only mirror).
    EXPECT_NE(h1, RunWithThreads("cantilever_2d.yaml",
                                 {beam[0], beam[1], "domain.ghost_nodes=mirror_velocity"}, 0.02, 2))
        << update;
  }
}

TEST(DeterminismTest, MuslSceneIsBitwiseIdenticalForOneAndTwoThreads) {
  const uint64_t h1 = RunWithThreads("two_disks_2d.yaml", {}, 1.5, 1);
  const uint64_t h2 = RunWithThreads("two_disks_2d.yaml", {}, 1.5, 2);
  EXPECT_EQ(h1, h2);
}

// Per-body velocity fields (body_contact): debris against an MPM barrier, past first contact.
TEST(DeterminismTest, BodyContactSceneIsBitwiseIdenticalForOneAndTwoThreads) {
  const std::vector<std::string> coarse = {"grid.cell_size=0.2"};
  const uint64_t h1 = RunWithThreads("debris_flexible_barrier_2d.yaml", coarse, 0.8, 1);
  const uint64_t h2 = RunWithThreads("debris_flexible_barrier_2d.yaml", coarse, 0.8, 2);
  EXPECT_EQ(h1, h2);
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

// Obstacles: an elastic block falls onto a fixed box and a rotating, translating cylinder
// (3-D, MUSL, friction): positions, velocities and every step's logged forces must not depend
// on the thread count (block-ordered node sums, chunk-ordered particle projection).
constexpr const char* kObstacleScene = R"(name: obstacle_determinism
dimension: 3
time: {end: 0.3, cfl: 0.4}
gravity: [0, -9.81, 0]
grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0, 0]
  max: [1.2, 1.0, 0.8]
  walls: {y-: {friction: 0.3}}
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 2.0e5, poisson_ratio: 0.3}
bodies:
  - name: block
    material: rubber
    region: {box: {min: [0.3, 0.45, 0.2], max: [0.8, 0.7, 0.6]}}
    particles_per_cell: 2
obstacles:
  - name: step
    shape: {box: {min: [0.2, 0, 0.1], max: [0.5, 0.3, 0.7]}}
    contact: {friction: 0.2}
  - name: roller
    shape: {cylinder: {base: [0.75, 0.25, 0.05], top: [0.75, 0.25, 0.75], radius: 0.12}}
    motion: {prescribed: {velocity: [0.1, 0, 0], angular_velocity_deg: [0, 0, 90]}}
    contact: {friction: 0.5, separable: false}
)";

uint64_t RunObstacleScene(int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  LoadedScene scene = LoadSceneFromString(kObstacleScene, "obstacle_determinism.yaml");
  uint64_t forces = 1469598103934665603ull;
  Real touched = 0;
  testing::RunUntil(scene, 0.3, [&](const State&, const StepReport& r) {
    for (const ObstacleForce& f : r.obstacles) {
      forces = Fnv1a(forces, f.force.data(), sizeof(Vec3));
      forces = Fnv1a(forces, f.torque.data(), sizeof(Vec3));
      forces = Fnv1a(forces, &f.contact_nodes, sizeof f.contact_nodes);
      touched += f.force.norm();
    }
  });
  EXPECT_GT(touched, 0) << "the block must hit the obstacles";
  return HashState(scene.state) ^ (forces * 31);
}

TEST(DeterminismTest, ObstacleSceneIsBitwiseIdenticalForOneAndTwoThreads) {
  EXPECT_EQ(RunObstacleScene(1), RunObstacleScene(2));
}

}  // namespace
}  // namespace surge

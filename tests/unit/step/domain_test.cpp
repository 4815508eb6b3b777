// Domain handling: particles leaving through an open side are removed and counted (or stop the
// run with on_exit: stop); a wall keeps them in; a body far from the origin costs the same grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "scene/scene.h"
#include "step/stages.h"
#include "step/step.h"
#include "transfer/transfer.h"

namespace surge {
namespace {

bool UsesFusedEndChecks(const Pipeline& pipeline) {
  for (const PipelineStage& s : pipeline)
    if (s.run == GridToParticleStressCheckStage) return true;
  return false;
}

// A 0.3 x 0.2 m block moving at 3 m/s towards x+ of a unit domain whose corner is at (o, o).
std::string MovingBlockText(const std::string& walls, const std::string& on_exit, double o = 0) {
  std::ostringstream s;
  s.precision(17);
  s << "name: exit_test\ndimension: 2\ntime: {end: 1.0, cfl: 0.4}\ngrid: {cell_size: 0.1}\n"
    << "domain:\n  min: [" << o << ", " << o << "]\n  max: [" << o + 1 << ", " << o + 1 << "]\n"
    << "  walls: " << walls << "\n  on_exit: " << on_exit << "\n"
    << "materials:\n  m: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, "
       "poisson_ratio: 0.3}\n"
    << "bodies:\n  - name: b\n    material: m\n    region: {box: {min: [" << o + 0.6 << ", "
    << o + 0.4 << "], max: [" << o + 0.9 << ", " << o + 0.6 << "]}}\n    velocity: [3, 0]\n";
  return s.str();
}

LoadedScene MovingBlock(const std::string& walls, const std::string& on_exit, double o = 0) {
  return LoadSceneFromString(MovingBlockText(walls, on_exit, o), "exit_test.yaml");
}

// The moving block (open sides, particles removed; at `speed` m/s) and an obstacle of `shape`.
LoadedScene BlockAnd(const std::string& shape, double speed = 3, bool gap_test = true) {
  std::string text = MovingBlockText("{}", "remove");
  text.replace(text.find("velocity: [3, 0]"), 16, "velocity: [" + std::to_string(speed) + ", 0]");
  text += "obstacles:\n  - {name: post, shape: " + shape + ", contact: {" +
          (gap_test ? "" : "faces: nodes, gap_test: false") + "}}\n";
  return LoadSceneFromString(text, "exit_test.yaml");
}

// A post from x = lo to hi, 0.3 <= y <= 0.7.
std::string Post(double lo, double hi) {
  std::ostringstream s;
  s.precision(17);
  s << "{box: {min: [" << lo << ", 0.3], max: [" << hi << ", 0.7]}}";
  return s.str();
}

HealthStatus RunFor(LoadedScene& scene, Real end) {
  const Pipeline pipeline = MakePipeline(scene.model);
  Workspace work;
  StepReport report;
  while (scene.state.time < end) {
    Step(scene.model, pipeline, scene.state, work, report);
    if (report.health.status != HealthStatus::kOk) return report.health.status;
  }
  return HealthStatus::kOk;
}

TEST(DomainTest, OpenSideRemovesAndCountsParticles) {
  LoadedScene scene = MovingBlock("{}", "remove");
  const size_t n0 = scene.state.particles.size();
  EXPECT_EQ(RunFor(scene, 0.2), HealthStatus::kOk);
  EXPECT_GT(scene.state.particles_removed, 0);
  EXPECT_EQ(scene.state.particles.size() + size_t(scene.state.particles_removed), n0);
  EXPECT_EQ(scene.state.groups[0].end, scene.state.particles.size());
  for (const Vec3& x : scene.state.particles.x) EXPECT_LE(x.x(), 1.0);
}

TEST(DomainTest, OpenSideStopsTheRunWhenAsked) {
  LoadedScene scene = MovingBlock("{}", "stop");
  EXPECT_EQ(RunFor(scene, 0.2), HealthStatus::kLeftDomain);
}

TEST(DomainTest, WallKeepsParticlesIn) {
  LoadedScene scene = MovingBlock("{x+: slip}", "stop");
  const size_t n0 = scene.state.particles.size();
  EXPECT_EQ(RunFor(scene, 0.2), HealthStatus::kOk);
  EXPECT_EQ(scene.state.particles.size(), n0);
  for (const Vec3& x : scene.state.particles.x) EXPECT_LE(x.x(), 1.0);
}

TEST(DomainTest, BodyFarFromOriginCostsTheSameGrid) {
  // 1024 m is a whole number of blocks (8 cells of 0.1 m = 0.8 m: 1280 blocks), so the block
  // layout relative to the body is the same and the active block count must be equal.
  LoadedScene near = MovingBlock("{}", "remove", 0.0);
  LoadedScene far = MovingBlock("{}", "remove", 1024.0);
  SparseGrid g_near, g_far;
  RebuildGrid(near.model, near.state.particles, g_near);
  RebuildGrid(far.model, far.state.particles, g_far);
  EXPECT_EQ(g_near.block_count(), g_far.block_count());
  EXPECT_LE(g_far.block_count(), 8u);
}

TEST(DomainTest, FusedEndChecksStillFindAnUnhealthyParticle) {
  // The block's pipeline runs the domain-exit and health tests inside G2P (no obstacles, no
  // anti-locking); a NaN stress spreads through P2G to the grid and back, and the health check
  // must still stop the step and name a particle.
  LoadedScene scene = MovingBlock("{x+: slip}", "stop");
  ASSERT_TRUE(UsesFusedEndChecks(MakePipeline(scene.model)));
  scene.state.particles.stress[3] = SymMat3(Mat3::Constant(std::nan("")));
  EXPECT_EQ(RunFor(scene, 0.01), HealthStatus::kNonFinite);
}

TEST(DomainTest, FusedEndChecksOnlyWhereNothingMovesEveryParticleAfterGridToParticle) {
  LoadedScene plain = MovingBlock("{}", "remove");
  EXPECT_TRUE(UsesFusedEndChecks(MakePipeline(plain.model)));
  // Particle shifting moves every particle after G2P: the tests then stay in their own stages.
  std::string text = MovingBlockText("{}", "remove");
  text.replace(text.find("cell_size: 0.1}"), 15, "cell_size: 0.1, shape_function: quadratic_bspline}");
  text.replace(text.find("poisson_ratio: 0.3}"), 19, "poisson_ratio: 0.3, particle_shifting: true}");
  LoadedScene shifting = LoadSceneFromString(text, "exit_test.yaml");
  EXPECT_FALSE(UsesFusedEndChecks(MakePipeline(shifting.model)));
  // An obstacle's projection does not: it tests again the particles it moves.
  LoadedScene post = BlockAnd(Post(0.1, 0.2));
  EXPECT_TRUE(UsesFusedEndChecks(MakePipeline(post.model)));
}

// Set before a run by the tests below: the particle the Teleport stage puts at `teleport_to`.
size_t teleport_particle = 0;
Vec3 teleport_to = Vec3::Zero();
void TeleportStage(const Model&, const StepContext&, State& s, Workspace&, StepReport&) {
  s.particles.x[teleport_particle] = teleport_to;
}

// The pipeline with every `from` stage replaced by `to` (nullptr: removed).
Pipeline Replace(Pipeline pipeline, StageFn from, StageFn to) {
  Pipeline out;
  for (PipelineStage s : pipeline) {
    if (s.run == from) {
      if (!to) continue;
      s.run = to;
    }
    out.push_back(s);
  }
  return out;
}

TEST(DomainTest, ParticleProjectedOutThroughAnOpenSideIsStillRemoved) {
  // G2P's end checks pass; then a particle is put inside the part of a disk beyond the open x+
  // side (centre x = 1.05, radius 0.1; the particle at x = 1.1), and the projection moves it out
  // along the radius to x = 1.15, still beyond the side. The stage tests the particles it moves
  // again, so DomainExitStage runs its pass and removes it.
  LoadedScene scene = BlockAnd("{sphere: {center: [1.05, 0.5], radius: 0.1}}");
  Pipeline pipeline = MakePipeline(scene.model);
  ASSERT_TRUE(UsesFusedEndChecks(pipeline));
  Pipeline with_teleport;
  for (const PipelineStage& s : pipeline) {
    if (s.run == ObstacleProjectionStage)
      with_teleport.push_back({Stage::kObstacleProjection, TeleportStage});
    with_teleport.push_back(s);
  }
  const Particles& P = scene.state.particles;
  teleport_particle = size_t(std::max_element(P.x.begin(), P.x.end(), [](const Vec3& a, const Vec3& b) {
                               return a.x() < b.x();
                             }) - P.x.begin());
  teleport_to = Vec3(1.1, 0.5, 0);
  const size_t n0 = P.size();
  Workspace work;
  StepReport report;
  Step(scene.model, with_teleport, scene.state, work, report);
  ASSERT_EQ(report.health.status, HealthStatus::kOk);
  EXPECT_EQ(scene.state.particles_removed, 1);
  EXPECT_EQ(P.size(), n0 - 1);
  for (const Vec3& x : P.x) EXPECT_LE(x.x(), 1.0);
}

TEST(DomainTest, FusedEndChecksWithAnObstacleGiveTheSameState) {
  // The block runs into the post; without the gap test, nodes are constrained only once they
  // lie inside it, so particles enter it and are projected out. The fused pipeline (checks in
  // G2P, again after the projection) and the one with the checks in their own stages end bitwise
  // equal.
  LoadedScene fused = BlockAnd(Post(0.95, 1.2), 20, false);
  LoadedScene plain = BlockAnd(Post(0.95, 1.2), 20, false);
  const Pipeline a = MakePipeline(fused.model);
  ASSERT_TRUE(UsesFusedEndChecks(a));
  const Pipeline b = Replace(a, GridToParticleStressCheckStage, GridToParticleStressStage);
  Workspace wa, wb;
  StepReport ra, rb;
  size_t projected = 0;
  while (fused.state.time < 0.1) {
    Step(fused.model, a, fused.state, wa, ra);
    Step(plain.model, b, plain.state, wb, rb);
    ASSERT_EQ(ra.health.status, HealthStatus::kOk);
    for (const auto& list : wa.contact.moved) projected += list.size();
  }
  EXPECT_GT(projected, 0u);
  ASSERT_EQ(fused.state.particles.size(), plain.state.particles.size());
  for (size_t p = 0; p < fused.state.particles.size(); ++p) {
    ASSERT_EQ(fused.state.particles.x[p], plain.state.particles.x[p]) << p;
    ASSERT_EQ(fused.state.particles.v[p], plain.state.particles.v[p]) << p;
  }
}

bool UsesAdvectChecks(const Pipeline& pipeline) {
  bool checks = false, advect = false;
  for (const PipelineStage& s : pipeline) {
    checks |= s.run == UpdateStressAdvectCheckStage;
    advect |= s.run == AdvectStage;
  }
  return checks && !advect;
}

// The moving block with APIC and MUSL: deferred advection, done by the stress update.
LoadedScene ApicMuslBlock(const std::string& on_exit) {
  std::string text = MovingBlockText("{}", on_exit);
  text.replace(text.find("cell_size: 0.1}"), 15, "cell_size: 0.1, transfer: apic, update: musl}");
  return LoadSceneFromString(text, "exit_test.yaml");
}

TEST(DomainTest, AdvectingStressUpdateRemovesLeavingParticlesAsTheAdvectStageDoes) {
  LoadedScene checked = ApicMuslBlock("remove");
  LoadedScene plain = ApicMuslBlock("remove");
  const Pipeline a = MakePipeline(checked.model);
  ASSERT_TRUE(UsesAdvectChecks(a));
  // The same cycle with the advection in its own stage right after the stress update.
  Pipeline b;
  for (const PipelineStage& s : a) {
    if (s.run != UpdateStressAdvectCheckStage) {
      b.push_back(s);
      continue;
    }
    b.push_back({s.stage, UpdateStressStage});
    b.push_back({Stage::kGridToParticle, AdvectStage});
  }
  const size_t n0 = checked.state.particles.size();
  Workspace wa, wb;
  StepReport ra, rb;
  while (checked.state.time < 0.2) {
    Step(checked.model, a, checked.state, wa, ra);
    Step(plain.model, b, plain.state, wb, rb);
    ASSERT_EQ(ra.health.status, HealthStatus::kOk);
  }
  EXPECT_GT(checked.state.particles_removed, 0);
  EXPECT_EQ(checked.state.particles_removed, plain.state.particles_removed);
  EXPECT_EQ(checked.state.particles.size() + size_t(checked.state.particles_removed), n0);
  ASSERT_EQ(checked.state.particles.size(), plain.state.particles.size());
  for (size_t p = 0; p < checked.state.particles.size(); ++p) {
    EXPECT_LE(checked.state.particles.x[p].x(), 1.0);
    ASSERT_EQ(checked.state.particles.x[p], plain.state.particles.x[p]) << p;
    ASSERT_EQ(checked.state.particles.v[p], plain.state.particles.v[p]) << p;
  }
}

TEST(DomainTest, AdvectingStressUpdateStillFindsAnUnhealthyParticle) {
  LoadedScene scene = ApicMuslBlock("stop");
  ASSERT_TRUE(UsesAdvectChecks(MakePipeline(scene.model)));
  scene.state.particles.stress[3] = SymMat3(Mat3::Constant(std::nan("")));
  EXPECT_EQ(RunFor(scene, 0.01), HealthStatus::kNonFinite);
}

}  // namespace
}  // namespace surge

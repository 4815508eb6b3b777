// Domain handling: particles leaving through an open side are removed and counted (or stop the
// run with on_exit: stop); a wall keeps them in; a body far from the origin costs the same grid.
#include <gtest/gtest.h>

#include <sstream>

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
LoadedScene MovingBlock(const std::string& walls, const std::string& on_exit, double o = 0) {
  std::ostringstream s;
  s.precision(17);
  s << "name: exit_test\ndimension: 2\ntime: {end: 1.0, cfl: 0.4}\ngrid: {cell_size: 0.1}\n"
    << "domain:\n  min: [" << o << ", " << o << "]\n  max: [" << o + 1 << ", " << o + 1 << "]\n"
    << "  walls: " << walls << "\n  on_exit: " << on_exit << "\n"
    << "materials:\n  m: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, "
       "poisson_ratio: 0.3}\n"
    << "bodies:\n  - name: b\n    material: m\n    region: {box: {min: [" << o + 0.6 << ", "
    << o + 0.4 << "], max: [" << o + 0.9 << ", " << o + 0.6 << "]}}\n    velocity: [3, 0]\n";
  return LoadSceneFromString(s.str(), "exit_test.yaml");
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

TEST(DomainTest, FusedEndChecksOnlyWhereNothingMovesParticlesAfterGridToParticle) {
  // An obstacle projects particles after G2P: the tests then stay in their own stages.
  LoadedScene plain = MovingBlock("{}", "remove");
  EXPECT_TRUE(UsesFusedEndChecks(MakePipeline(plain.model)));
  std::ostringstream s;
  s << "name: exit_test\ndimension: 2\ntime: {end: 1.0, cfl: 0.4}\ngrid: {cell_size: 0.1}\n"
    << "domain: {min: [0, 0], max: [1, 1]}\n"
    << "materials:\n  m: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, "
       "poisson_ratio: 0.3}\n"
    << "bodies:\n  - {name: b, material: m, region: {box: {min: [0.6, 0.4], max: [0.9, 0.6]}}}\n"
    << "obstacles:\n  - {name: post, shape: {box: {min: [0.1, 0.1], max: [0.2, 0.2]}}}\n";
  LoadedScene with_obstacle = LoadSceneFromString(s.str(), "exit_test.yaml");
  EXPECT_FALSE(UsesFusedEndChecks(MakePipeline(with_obstacle.model)));
}

}  // namespace
}  // namespace surge

// StepScratchFor (step.h), the memory estimate's per-particle step scratch, against what the
// pipeline's stages actually fill: after a few steps every scratch array StepScratchFor names
// holds one entry per particle and every other one is empty (the estimate neither misses an
// array nor counts one the run does not hold).
#include <gtest/gtest.h>

#include <string>

#include "scene/memory_estimate.h"
#include "scene/scene.h"
#include "step/step.h"

namespace surge {
namespace {

// A 2-D elastic block falling in a box, with a material's extra keys, the grid's update scheme and
// extra top-level keys.
LoadedScene Block(const std::string& material_keys, const std::string& update,
                  const std::string& extra = "") {
  const std::string yaml =
      "name: scratch_test\ndimension: 2\ntime: {end: 1.0, cfl: 0.4}\n"
      "gravity: [0, -10]\n"
      "grid: {cell_size: 0.1, update: " + update + "}\n"
      "domain: {min: [0, 0], max: [1, 1], walls: {x-: slip, x+: slip, y-: slip, y+: slip}}\n"
      "materials:\n  m: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, "
      "poisson_ratio: 0.3" + material_keys + "}\n"
      "bodies:\n  - name: b\n    material: m\n    region: {box: {min: [0.3, 0.2], max: [0.7, 0.5]}}\n" +
      extra;
  return LoadSceneFromString(yaml, "scratch_test.yaml");
}

void ExpectScratchAsEstimated(const std::string& material_keys, const std::string& update,
                              const std::string& extra = "") {
  SCOPED_TRACE(update + " with" + material_keys + extra);
  LoadedScene scene = Block(material_keys, update, extra);
  const StepScratch expected = StepScratchFor(scene.model);
  const Pipeline pipeline = MakePipeline(scene.model);
  Workspace work;
  StepReport report;
  for (int i = 0; i < 3; ++i) {
    Step(scene.model, pipeline, scene.state, work, report);
    ASSERT_EQ(report.health.status, HealthStatus::kOk);
  }
  const size_t n = scene.state.particles.size();
  ASSERT_GT(n, 0u);
  const auto held = [&](size_t size) { return size == n; };
  const auto empty_or_held = [&](size_t size) { return size == 0 || size == n; };
  for (size_t size : {work.velocity_gradient.size(), work.x_new.size(),
                      work.antilocking.theta.size(), work.antilocking.tensor.size(),
                      work.antilocking.inv_stretch.size(), work.antilocking.theta_bar.size(),
                      work.shifting.shift.size()})
    EXPECT_TRUE(empty_or_held(size)) << size;
  EXPECT_EQ(held(work.velocity_gradient.size()), expected.velocity_gradient);
  EXPECT_EQ(held(work.x_new.size()), expected.x_n);
  EXPECT_EQ(held(work.antilocking.theta.size()), expected.theta);
  EXPECT_EQ(held(work.antilocking.tensor.size()), expected.tensor);
  EXPECT_EQ(held(work.antilocking.tensor_ok.size()), expected.tensor);
  EXPECT_EQ(held(work.antilocking.inv_stretch.size()), expected.inv_stretch);
  EXPECT_EQ(held(work.antilocking.theta_bar.size()), expected.theta_bar);
  EXPECT_EQ(held(work.shifting.shift.size()), expected.shift);
  // Grid nodes: v_{i,n} is held; p_i beside it only with node_momentum (SparseGrid::momentum
  // hands its buffer to velocity), the nodal reaction only with node_reaction.
  const SparseGrid& g = work.grid;
  const size_t nodes = g.mass.size();
  ASSERT_GT(nodes, 0u);
  EXPECT_EQ(g.velocity.size(), nodes);
  EXPECT_EQ(g.velocity_new.size(), nodes);
  EXPECT_EQ(g.momentum.capacity() > 0, expected.node_momentum);
  EXPECT_EQ(g.reaction.capacity() > 0, expected.node_reaction);
  if (expected.node_reaction) {
    EXPECT_EQ(g.reaction.size(), nodes);
  }
}

TEST(StepScratchTest, EstimateNamesTheArraysEachPipelineFills) {
  ExpectScratchAsEstimated("", "usl");  // the stress update fused into G2P: no L_p, no x_n
  ExpectScratchAsEstimated("", "musl");
  ExpectScratchAsEstimated("", "musl, transfer: flip");
  ExpectScratchAsEstimated(", antilocking: {method: node, strain: increment}", "usl, transfer: flip");
  ExpectScratchAsEstimated(", bulk_viscosity: {}", "usl");
  ExpectScratchAsEstimated(", antilocking: {method: node, strain: increment}", "usl");
  ExpectScratchAsEstimated(", antilocking: {method: cell, approach: constant_volumetric}", "usl");
  ExpectScratchAsEstimated(", antilocking: {method: hybrid, strain: increment}", "usl");
  ExpectScratchAsEstimated(", antilocking: {method: smoothing}", "musl");
  ExpectScratchAsEstimated(", particle_shifting: true", "usl");
  const std::string sensor = "sensors:\n  - {name: floor, box: {min: [0, 0], max: [1, 0.15]}}\n";
  ExpectScratchAsEstimated("", "usl", sensor);
  ExpectScratchAsEstimated("", "musl", sensor);
}

TEST(StepScratchTest, GridIsEstimatedWithoutUnusedNodeArrays) {
  LoadedScene usl = Block("", "usl");
  LoadedScene musl = Block("", "musl");
  LoadedScene sensed =
      Block("", "usl", "sensors:\n  - {name: floor, box: {min: [0, 0], max: [1, 0.15]}}\n");
  const double usl_block = BytesPerBlock(0, 2, StepScratchFor(usl.model));
  // MUSL's second p_i buffer and the sensors' nodal reaction: 3 doubles a node each (8^2 nodes).
  EXPECT_DOUBLE_EQ(BytesPerBlock(0, 2, StepScratchFor(musl.model)) - usl_block, 64 * 3 * sizeof(Real));
  EXPECT_DOUBLE_EQ(BytesPerBlock(0, 2, StepScratchFor(sensed.model)) - usl_block, 64 * 3 * sizeof(Real));
  EXPECT_LT(BytesPerBlock(0, 2, StepScratchFor(musl.model)), BytesPerBlock(0, 2));
}

TEST(StepScratchTest, FusedRunIsEstimatedWithoutTheVelocityGradient) {
  LoadedScene fused = Block("", "usl");
  LoadedScene musl = Block("", "musl");  // APIC: advection deferred, no x_{n+1} array
  LoadedScene musl_flip = Block("", "musl, transfer: flip");
  ASSERT_EQ(musl.model.transfer, TransferScheme::kApic);
  EXPECT_TRUE(DeferredAdvection(musl.model));
  EXPECT_FALSE(DeferredAdvection(musl_flip.model));
  EXPECT_FALSE(DeferredAdvection(fused.model));
  const ParticleLayout& layout = fused.state.particles.layout;
  // L_p (9 doubles), and x_{n+1} (3) with FLIP; the default scratch is the upper bound.
  const double fused_bytes = BytesPerParticle(layout, StepScratchFor(fused.model));
  EXPECT_DOUBLE_EQ(BytesPerParticle(layout, StepScratchFor(musl.model)) - fused_bytes,
                   9 * sizeof(Real));
  EXPECT_DOUBLE_EQ(BytesPerParticle(layout, StepScratchFor(musl_flip.model)) - fused_bytes,
                   12 * sizeof(Real));
  EXPECT_LT(BytesPerParticle(layout, StepScratchFor(musl_flip.model)), BytesPerParticle(layout));
}

}  // namespace
}  // namespace surge

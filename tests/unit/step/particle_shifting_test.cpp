// Particle shifting (src/stabilize/particle_shifting.h): the node volumes next to walls, no shift
// for a regular lattice of particles, and a crowded cluster pushed apart so that the excess falls.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "stabilize/particle_shifting.h"
#include "step/step.h"

namespace surge {
namespace {

TEST(ParticleShiftingTest, BsplineTailIsTheIntegralOfTheKernel) {
  EXPECT_DOUBLE_EQ(QuadraticBsplineTail(-2.0), 1.0);
  EXPECT_DOUBLE_EQ(QuadraticBsplineTail(-1.5), 1.0);
  EXPECT_DOUBLE_EQ(QuadraticBsplineTail(0.0), 0.5);
  EXPECT_DOUBLE_EQ(QuadraticBsplineTail(1.5), 0.0);
  EXPECT_NEAR(QuadraticBsplineTail(1.0), 1.0 / 48, 1e-15);
  EXPECT_NEAR(QuadraticBsplineTail(-1.0), 47.0 / 48, 1e-15);
  // -dTail/da = N(a) (midpoint differences), across the pieces and their joints at +-0.5.
  for (Real a : {-1.2, -0.5, -0.3, 0.0, 0.4, 0.5, 0.9, 1.4}) {
    const Real e = 1e-6, fa = std::abs(a);
    const Real n = fa < 0.5 ? 0.75 - a * a : 0.5 * (1.5 - fa) * (1.5 - fa);
    EXPECT_NEAR(-(QuadraticBsplineTail(a + e) - QuadraticBsplineTail(a - e)) / (2 * e), n, 1e-8)
        << a;
  }
}

// A 2-D water block filling a walled box [0, 1] x [0, 1] at h = 0.1 up to `top`, n particles per
// cell per direction; optionally one more particle crowded into the block.
LoadedScene Tank(int n, Real top, bool shifting) {
  const std::string yaml =
      "name: shifting_test\ndimension: 2\ntime: {end: 1.0}\ngravity: [0, -10]\n"
      "grid: {cell_size: 0.1}\n"
      "domain: {min: [0, 0], max: [1, 1], walls: {x-: slip, x+: slip, y-: slip, y+: slip}}\n"
      "materials:\n  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 1.0e6, "
      "viscosity: 0.001, particle_shifting: " + std::string(shifting ? "true" : "false") + "}\n"
      "bodies:\n  - name: w\n    material: water\n    particles_per_cell: " + std::to_string(n) +
      "\n    region: {box: {min: [0, 0], max: [1, " + std::to_string(top) + "]}}\n";
  return LoadSceneFromString(yaml, "shifting_test.yaml");
}

// The grid binned at the particles (the first stages of a step), then the shift.
ShiftingScratch ShiftOf(LoadedScene& scene, Workspace& work) {
  const Pipeline pipeline = MakePipeline(scene.model);
  StepContext ctx;
  ctx.dt = 1e-4;
  ctx.dx = scene.model.dx;
  ctx.inv_dx = 1 / scene.model.dx;
  StepReport report;
  for (const PipelineStage& s : pipeline) {
    // The compute stage comes right before G2P.
    if (s.stage == Stage::kParticleShifting || s.stage == Stage::kGridToParticle) break;
    s.run(scene.model, ctx, scene.state, work, report);
  }
  ComputeParticleShift(scene.model, ctx, scene.state.groups, scene.state.particles,
                       scene.state.rigid, work.grid, work.shifting);
  return work.shifting;
}

TEST(ParticleShiftingTest, RegularLatticeAgainstWallsIsNotShifted) {
  for (int n : {2, 3}) {
    SCOPED_TRACE(n);
    LoadedScene scene = Tank(n, 0.5, true);
    Workspace work;
    const ShiftingScratch s = ShiftOf(scene, work);
    EXPECT_EQ(s.excess_sq, 0.0);
    for (const Vec3& d : s.shift) EXPECT_EQ(d.norm(), 0.0);
  }
}

TEST(ParticleShiftingTest, CrowdedParticlesMoveApartAndTheExcessFalls) {
  LoadedScene scene = Tank(2, 0.5, true);
  Particles& P = scene.state.particles;
  // Squeeze the particles of the cell [0.4, 0.5] x [0.2, 0.3] towards its centre by half.
  const Vec3 centre(0.45, 0.25, 0);
  std::vector<size_t> squeezed;
  for (size_t p = 0; p < P.size(); ++p) {
    if (std::abs(P.x[p].x() - centre.x()) < 0.05 && std::abs(P.x[p].y() - centre.y()) < 0.05) {
      P.x[p] = centre + 0.5 * (P.x[p] - centre);
      squeezed.push_back(p);
    }
  }
  ASSERT_EQ(squeezed.size(), 4u);
  Workspace work;
  const ShiftingScratch before = ShiftOf(scene, work);
  ASSERT_GT(before.excess_sq, 0);
  squeezed.clear();  // the step's first stages reorder the particles
  for (size_t p = 0; p < P.size(); ++p)
    if ((P.x[p] - centre).norm() < 0.03) squeezed.push_back(p);
  ASSERT_EQ(squeezed.size(), 4u);
  for (size_t p : squeezed) {  // each squeezed particle moves away from the centre
    EXPECT_GT(before.shift[p].dot(P.x[p] - centre), 0) << p;
  }
  ApplyParticleShift(scene.model, P, before);
  Workspace again;
  const ShiftingScratch after = ShiftOf(scene, again);
  EXPECT_LT(after.excess_sq, 0.5 * before.excess_sq);
  // Without the material's key nothing moves (the excess is still measured).
  LoadedScene off = Tank(2, 0.5, false);
  off.state.particles.x = P.x;  // the same seeding, in the order of the shifted scene
  Workspace w_off;
  const ShiftingScratch none = ShiftOf(off, w_off);
  EXPECT_GT(none.excess_sq, 0);
  for (const Vec3& d : none.shift) EXPECT_EQ(d.norm(), 0.0);
}

}  // namespace
}  // namespace surge

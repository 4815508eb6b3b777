// Bar under an end traction (particle tractions, Mast 2013 App. B.2.9, ramped as App. B.2.3
// ExternalForceRamp): a bar fixed at x = 0 with traction t on its x+ face. Statics: end
// displacement t L / E and wall reaction t A. The load is ramped over several periods, so the
// bar stays close to the static solution; checked on the time average (2 %).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr const char* kScene = R"(name: traction_bar
dimension: 2
time: {end: 1.0, cfl: 0.4}
gravity_ramp: 0.5
grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [1.5, 0.5]
  walls: {x-: no_slip}
materials:
  rubber: {model: linear_elastic, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.0}
bodies:
  - name: bar
    material: rubber
    region: {box: {min: [0, 0.1], max: [1.0, 0.3]}}
    particles_per_cell: 2
    tractions:
      - {face: x+, traction: [1.0e4, 0]}
)";

TEST(TractionBarTest, EndDisplacementAndReactionMatchStatics) {
  LoadedScene scene = LoadSceneFromString(kScene, "traction_bar.yaml");
  const Real t = 1e4, L = 1.0, E = 1e6, A = 0.2;
  const Particles& P0 = scene.state.particles;
  // Tip particles by id: the engine reorders particles, indices are not stable.
  std::vector<bool> tip(P0.size(), false);
  Real x0 = 0;
  for (size_t p = 0; p < P0.size(); ++p)
    if (P0.x[p].x() > L - 0.02) {
      tip[P0.id[p]] = true;
      x0 = P0.x[p].x();
    }
  Real disp = 0, reaction = 0;
  int samples = 0;
  testing::RunUntil(scene, 1.0, [&](const State& s, const StepReport& r) {
    if (s.time < 0.6) return;
    Real x = 0;
    int count = 0;
    for (size_t p = 0; p < s.particles.size(); ++p)
      if (tip[s.particles.id[p]]) {
        x += s.particles.x[p].x();
        ++count;
      }
    disp += x / count - x0;
    reaction += r.walls.force[int(Face::kXMin)].x();  // the bar pulls the wall along +x
    ++samples;
  });
  disp /= samples;
  reaction /= samples;
  std::printf("traction bar: end displacement %.5g m (t L / E = %.5g), wall reaction %.5g N/m "
              "(t A = %.5g)\n", disp, t * L / E, reaction, t * A);
  EXPECT_NEAR(disp, t * L / E, 0.02 * t * L / E);
  EXPECT_NEAR(reaction, t * A, 0.02 * t * A);
}

}  // namespace
}  // namespace surge

// Sliding block (shared/VALIDATION.md): a block sliding on a Coulomb floor decelerates at
// mu g until it stops: v(t) = v0 - mu g t (the inclined-plane case a = g (sin th - mu cos th)
// with th = 0). Checks the friction wall (seed Planar with mu > 0, spec §5.3) and its reaction:
// the floor's tangential reaction equals mu times its normal reaction while sliding.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr const char* kScene = R"(name: sliding_block
dimension: 2
time: {end: 0.5, cfl: 0.4}
gravity: [0, -9.81]
grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [4, 1]
  walls: {y-: {friction: 0.3}}
materials:
  steel_like: {model: neo_hookean, density: 2000, youngs_modulus: 5.0e7, poisson_ratio: 0.3}
bodies:
  - name: block
    material: steel_like
    region: {box: {min: [0.5, 0], max: [1.0, 0.25]}}
    particles_per_cell: 2
    velocity: [2.0, 0]
)";

TEST(SlidingBlockTest, DeceleratesAtMuG) {
  LoadedScene scene = LoadSceneFromString(kScene, "sliding_block.yaml");
  const Real mu = 0.3, g = 9.81, v0 = 2.0;
  Real impulse_t = 0, impulse_n = 0;
  const Real t_end = 0.4;  // stops at v0 / (mu g) = 0.68 s
  testing::RunUntil(scene, t_end, [&](const State& s, const StepReport& r) {
    impulse_t += s.dt * r.walls.force[int(Face::kYMin)].x();
    impulse_n += s.dt * r.walls.force[int(Face::kYMin)].y();
  });
  Real m = 0, p = 0;
  for (size_t i = 0; i < scene.state.particles.size(); ++i) {
    m += scene.state.particles.mass[i];
    p += scene.state.particles.mass[i] * scene.state.particles.v[i].x();
  }
  const Real v = p / m, expected = v0 - mu * g * t_end;
  std::printf("sliding block: v(%.2f s) = %.4f m/s, closed form %.4f m/s (error %.2f %%); "
              "floor impulse ratio t/n = %.4f\n",
              t_end, v, expected, 100 * (v - expected) / expected, impulse_t / -impulse_n);
  EXPECT_NEAR(v, expected, 0.02 * expected);
  // Mean reaction on the floor: normal = weight, tangential = mu x normal, along +x (the block
  // drags the floor forward). Tolerance 2 %: the initial settling bounce.
  EXPECT_NEAR(-impulse_n / t_end, m * g, 0.02 * m * g);
  EXPECT_NEAR(impulse_t / -impulse_n, mu, 0.02 * mu);
}

}  // namespace
}  // namespace surge

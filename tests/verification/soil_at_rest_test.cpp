// Soil at rest behind a wall and the hydrostatic column (shared/VALIDATION.md): a linear-elastic
// column of height h between frictionless walls, started from the geostatic (K0) state
// sigma_v = -rho g d, sigma_h = K0 sigma_v with the elastic K0 = nu / (1 - nu). It must stay at
// rest: the floor carries the weight rho g h w, each side wall the thrust 1/2 K0 rho g h^2 per
// metre (tolerance 10 %, VALIDATION.md), and the mid-depth vertical stress is -rho g h/2 (2 %).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr const char* kScene = R"(name: soil_at_rest
dimension: 2
time: {end: 0.5, cfl: 0.4}
gravity: [0, -9.81]
grid: {cell_size: 0.1, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [1, 3]
  walls: {x-: slip, x+: slip, y-: slip}
materials:
  soil: {model: linear_elastic, density: 2000, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
bodies:
  - name: column
    material: soil
    region: {box: {min: [0, 0], max: [1, 2]}}
    particles_per_cell: 2
    initial_stress: {geostatic: {k0: 0.4285714285714286}}
)";

TEST(SoilAtRestTest, GeostaticColumnStaysAtRestWithAnalyticWallLoads) {
  LoadedScene scene = LoadSceneFromString(kScene, "soil_at_rest.yaml");
  const Real rho = 2000, g = 9.81, h = 2.0, w = 1.0, k0 = 0.3 / 0.7;
  Real floor = 0, side = 0, vmax = 0;
  int samples = 0;
  testing::RunUntil(scene, 0.5, [&](const State& s, const StepReport& r) {
    for (const Vec3& v : s.particles.v) vmax = std::max(vmax, v.norm());
    if (s.time < 0.25) return;  // average over the second half
    floor += -r.walls.force[int(Face::kYMin)].y();
    side += r.walls.force[int(Face::kXMax)].x();
    ++samples;
  });
  floor /= samples;
  side /= samples;
  Real syy = 0, count = 0;
  const Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p)
    if (std::abs(P.x[p].y() - h / 2) < 0.05) {
      syy += P.stress[p](1, 1);
      ++count;
    }
  syy /= count;
  const Real weight = rho * g * h * w, thrust = 0.5 * k0 * rho * g * h * h;
  std::printf("soil at rest: floor %.4g N/m (weight %.4g), side thrust %.4g N/m (1/2 K0 rho g h^2 = "
              "%.4g), mid-depth sigma_yy %.4g Pa (%.4g), max |v| %.3g m/s\n",
              floor, weight, side, thrust, syy, -rho * g * h / 2, vmax);
  EXPECT_NEAR(floor, weight, 0.02 * weight);
  EXPECT_NEAR(side, thrust, 0.10 * thrust);
  EXPECT_NEAR(syy, -rho * g * h / 2, 0.02 * rho * g * h / 2);
  // Without the K0 initial state the column would settle under its own weight with velocities of
  // order settlement x frequency; the geostatic start must stay far quieter than that run.
  std::string text = kScene;
  text.erase(text.find("    initial_stress:"));
  LoadedScene plain = LoadSceneFromString(text, "soil_at_rest_plain.yaml");
  Real vmax_plain = 0;
  testing::RunUntil(plain, 0.5, [&](const State& s, const StepReport&) {
    for (const Vec3& v : s.particles.v) vmax_plain = std::max(vmax_plain, v.norm());
  });
  std::printf("soil at rest: max |v| without the geostatic start %.3g m/s\n", vmax_plain);
  EXPECT_LT(vmax, 0.2 * vmax_plain) << "the geostatic column should stay (nearly) at rest";
}

}  // namespace
}  // namespace surge

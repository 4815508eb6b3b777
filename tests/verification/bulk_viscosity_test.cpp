// Artificial bulk viscosity (docs/antilocking.md "Artificial bulk viscosity"; von Neumann &
// Richtmyer 1950, Wilkins 1980, LS-DYNA Theory Manual): a 1-D elastic bar (plane strain, nu = 0,
// E = 100 Pa, rho = 1 kg/m^3, c = 10 m/s, L = 25 m, dx = 0.25 m, FLIP) moving at v0 onto a fixed
// wall. A compression front runs into the bar at c (it is at x = (c - v0) t); behind it the exact state is v = 0 and
// sigma = -rho c v0 (the impact stress). Explicit MPM rings behind the front (Gibbs-type overshoot
// of the stress, particles bouncing back); the bulk viscosity q must reduce both overshoots, leave
// the mean stress behind the front (the jump condition) and the front speed alone, and the
// time step must shrink by the LS-DYNA bound l / (Q + sqrt(Q^2 + c^2)).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr Real kRho = 1, kC = 10, kL = 25;

std::string Scene(Real v0, const std::string& viscosity) {
  return R"(name: bar_impact
dimension: 2
time: {end: 1.5, cfl: 0.4}
grid: {cell_size: 0.25, shape_function: quadratic_bspline, transfer: flip}
domain:
  min: [0, 0]
  max: [30, 1]
  walls: {x-: no_slip}
materials:
  bar: {model: linear_elastic, density: 1.0, youngs_modulus: 100.0, poisson_ratio: 0.0)" +
         viscosity + R"(}
bodies:
  - name: bar
    material: bar
    region: {box: {min: [0, 0.25], max: [25, 0.75]}}
    particles_per_cell: 2
    velocity: [)" + std::to_string(-v0) + R"(, 0]
)";
}

struct Impact {
  Real stress_overshoot = 0;    // max over t, particles behind the front: -sigma_xx/(rho c v0) - 1
  Real velocity_overshoot = 0;  // max over t, particles behind the front: |v_x| / v0 (exact 0)
  Real mean_stress = 0;         // mean -sigma_xx / (rho c v0) behind the front at the end (exact 1)
  Real front = 0;               // position of the front at the end [m] (exact c t)
  Real mean_dt = 0;             // [s]
};

Impact RunImpact(Real v0, const std::string& viscosity) {
  LoadedScene scene = LoadSceneFromString(Scene(v0, viscosity), "bar_impact.yaml");
  const Real jump = kRho * kC * v0;
  Impact out;
  int steps = 0;
  testing::RunUntil(scene, 1.5, [&](const State& s, const StepReport&) {
    ++steps;
    const Particles& P = s.particles;
    const Real behind = kC * s.time - 2.0;  // 8 cells behind the exact front x = c t
    for (size_t p = 0; p < P.size(); ++p) {
      if (P.x[p].x() > behind || P.x[p].x() < 1.0) continue;  // 4 cells off the wall
      out.stress_overshoot = std::max(out.stress_overshoot, -P.stress[p](0, 0) / jump - 1);
      out.velocity_overshoot = std::max(out.velocity_overshoot, std::abs(P.v[p].x()) / v0);
    }
  });
  const Particles& P = scene.state.particles;
  const Real t = scene.state.time;
  Real sum = 0;
  int count = 0;
  for (size_t p = 0; p < P.size(); ++p) {
    if (P.x[p].x() < kC * t - 2.0 && P.x[p].x() > 1.0) {
      sum += -P.stress[p](0, 0) / jump;
      ++count;
    }
    if (-P.stress[p](0, 0) > 0.5 * jump) out.front = std::max(out.front, P.x[p].x());
  }
  out.mean_stress = sum / count;
  out.mean_dt = t / steps;
  return out;
}

TEST(BulkViscosityTest, ReducesRingingBehindAnImpactFront) {
  for (const Real v0 : {0.1, 1.0}) {  // weak (v0/c = 1 %) and strong (10 %) impacts
    const Impact plain = RunImpact(v0, "");
    const Impact lsdyna = RunImpact(v0, ", bulk_viscosity: {quadratic: 1.5, linear: 0.06}");
    const Impact strong = RunImpact(v0, ", bulk_viscosity: {quadratic: 1.5, linear: 0.2}");
    for (const auto& [name, r] : {std::pair{"none", &plain}, {"c1 0.06", &lsdyna}, {"c1 0.2", &strong}}) {
      std::printf("bar impact v0 = %.1f m/s, %-7s: stress overshoot %5.2f %%, velocity overshoot "
                  "%5.2f %% of v0, mean stress behind the front %.4f (exact 1), front %.3f m "
                  "(exact %.2f), mean dt %.4g s\n",
                  v0, name, 100 * r->stress_overshoot, 100 * r->velocity_overshoot, r->mean_stress,
                  r->front, (kC - v0) * 1.5, r->mean_dt);
    }
    EXPECT_LT(lsdyna.stress_overshoot, 0.8 * plain.stress_overshoot) << "v0 " << v0;
    EXPECT_LT(lsdyna.velocity_overshoot, 0.8 * plain.velocity_overshoot) << "v0 " << v0;
    EXPECT_LT(strong.stress_overshoot, 0.8 * lsdyna.stress_overshoot) << "v0 " << v0;
    // q must not change the jump condition or the front speed (within a cell).
    EXPECT_NEAR(lsdyna.mean_stress, plain.mean_stress, 0.01) << "v0 " << v0;
    EXPECT_NEAR(strong.mean_stress, plain.mean_stress, 0.02) << "v0 " << v0;
    EXPECT_NEAR(lsdyna.front, plain.front, 0.25) << "v0 " << v0;
    EXPECT_LT(lsdyna.mean_dt, plain.mean_dt) << "the time step must account for q";
  }
}

}  // namespace
}  // namespace surge

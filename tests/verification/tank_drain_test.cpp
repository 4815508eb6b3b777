// Tank drain (Mast 2013 §6.1.3; spec seed-validation-cases.md §3.3, B3): scenes/tank_drain_2d.yaml
// at 3 x 3 particles per cell (the scene has the seed's 5 x 5). The half tank (4 x 4 m of water,
// drain 0.5 m wide at the symmetry plane) is settled by local damping with the drain plugged,
// then the plug drops at 0.5 s. While the water drains, the side-wall reaction must stay the
// hydrostatic triangle of the current depth h_w at the wall (seed: "triangular ... appropriate
// magnitude with respect to basic hydrostatics"; no number given). Checked at t = 1.5, 2.0, 2.5 s
// (means over 0.1 s windows):
//   - the resultant F against 1/2 rho g h_w^2: within [0.97, 1.03] (measured 0.99-1.02);
//   - the shape: the reaction on each of the three lower one-metre bands of the wall (force
//     sensors) against the hydrostatic pressure integrated over the band, within [0.97, 1.03]
//     (measured 0.98-1.03); the top band holds the free surface and is printed only;
//   - the floor's reaction against the weight of the water still in the tank (y > 0): 3 %.
// h_w = the highest particle within a cell of the wall + half a particle spacing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr Real kRho = 997.5, kG = 9.81;

// rho g int_a^b (h - y) dy over the part of [a, b] below h [N/m].
Real Hydrostatic(Real a, Real b, Real h) {
  b = std::min(b, h);
  if (b <= a) return 0;
  return kRho * kG * ((h * b - b * b / 2) - (h * a - a * a / 2));
}

// Runs the drain and checks the ratios against [lo, hi] (wall and the three lower bands).
void CheckDrain(const std::vector<std::string>& extra, Real lo, Real hi) {
  const int ppc = 3;
  std::vector<std::string> overrides = {"bodies.0.particles_per_cell=" + std::to_string(ppc)};
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  LoadedScene scene = LoadScene(testing::ScenePath("tank_drain_2d.yaml"), overrides);
  ASSERT_EQ(scene.model.sensors.size(), 4u);
  const Real spacing = scene.model.dx / ppc;
  // Tributary heights of the sensor bands (node rows 0-0.75, 1-1.75, 2-2.75, 3-4.75 m).
  const Real edges[5] = {0, 0.875, 1.875, 2.875, 10};
  // Ratios averaged over the steps of a 0.1 s window centred on each time (the single-step
  // reactions carry the particle noise of the flow).
  const Real times[3] = {1.5, 2.0, 2.5};
  struct Sums {
    Real wall = 0, band[4] = {0, 0, 0, 0}, floor = 0, hw = 0;
    int n = 0;
  } sums[3];
  testing::RunUntil(scene, 2.55, [&](const State& s, const StepReport& r) {
    int w = -1;
    for (int k = 0; k < 3; ++k)
      if (std::abs(s.time - times[k]) <= 0.05) w = k;
    if (w < 0) return;
    const Particles& P = s.particles;
    Real top = -1, in_tank = 0;
    for (size_t p = 0; p < P.size(); ++p) {
      if (P.x[p].x() > 4.0 - scene.model.dx && P.x[p].y() > 0) top = std::max(top, P.x[p].y());
      if (P.x[p].y() > 0) in_tank += P.mass[p];
    }
    const Real hw = top + spacing / 2;
    Sums& S = sums[w];
    S.wall += r.walls.force[int(Face::kXMax)].x() / (0.5 * kRho * kG * hw * hw);
    for (int k = 0; k < 4; ++k)
      S.band[k] += r.sensors[k].force.x() / Hydrostatic(edges[k], edges[k + 1], hw);
    S.floor += -r.obstacles[0].force.y() / (in_tank * kG);  // obstacle 0: the floor
    S.hw += hw;
    ++S.n;
  });
  int checked = 0, failures = 0;
  for (int w = 0; w < 3; ++w) {
    const Sums& S = sums[w];
    if (S.n == 0) continue;
    const Real n = S.n, ratio = S.wall / n, floor = S.floor / n;
    Real band[4];
    for (int k = 0; k < 4; ++k) band[k] = S.band[k] / n;
    std::printf("tank drain t = %.1f s (%d steps): h_w %.3f m, wall / (1/2 rho g h_w^2) %.3f; bands "
                "(0-1, 1-2, 2-3, 3- m) / hydrostatic %.3f %.3f %.3f %.3f; floor / weight in the "
                "tank %.4f\n",
                times[w], S.n, S.hw / n, ratio, band[0], band[1], band[2], band[3], floor);
    ++checked;
    failures += !(ratio > lo && ratio < hi);
    for (int k = 0; k < 3; ++k) failures += !(band[k] > lo && band[k] < hi);
    failures += !(std::abs(floor - 1) < 0.03);
  }
  EXPECT_EQ(checked, 3);
  EXPECT_EQ(failures, 0) << "see the printed ratios";
}

// The scene as shipped: the settle recipe of docs/antilocking.md ("Linear node fit"), the ghost
// nodes of the frictionless walls folded into their mirrors (domain.ghost_nodes: fold_all,
// docs/walls.md) and the linear node fit. Measured 2026-12-07: wall 0.993 / 1.006 / 1.015 of
// hydrostatic at 1.5 / 2.0 / 2.5 s, the three lower bands 0.983-1.026 (the fold with node AS1:
// 0.988-0.999 and 0.981-1.002).
TEST(TankDrainTest, SideWallReactionStaysHydrostaticWhileDraining) { CheckDrain({}, 0.97, 1.03); }

// The problem the recipe removes: with the default ghost nodes (the separable side wall's ghosts
// get the velocity mirror only) the wall drags the water flowing down along it (v_y at mid-depth
// -0.075 m/s next to the wall against -0.30 m/s 1-2 m away) and its reaction is 9 % low.
// Measured 2026-12-07 (node AS1): wall 0.915 / 0.919 / 0.923, the lower bands 0.894-0.937.
TEST(TankDrainTest, DefaultGhostNodesLeaveTheSideWallReactionNinePercentLow) {
  CheckDrain({"domain.ghost_nodes=mirror", "materials.water.antilocking={method: node}"}, 0.85,
             0.95);
}

}  // namespace
}  // namespace surge

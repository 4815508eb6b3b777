// 2-D dam break (Mast 2013 §6.1.1; spec seed-validation-cases.md §3.1, B1) with the weakly
// compressible Newtonian fluid at a reduced bulk modulus K = 2e6 Pa (scenes/dam_break_2d.yaml).
//  1. The front advances and stays below the Ritter shallow-water bound L = 1 + 2T.
//  2. In a box twice the column width the water settles to depth h = h0 l0 / W; the mean base
//     pressure (floor wall reaction / width, averaged over the last 0.5 s) equals rho0 g h within
//     2 %. The reduced K is for speed (dt ~ 30x the real-water step); it does not change the
//     hydrostatic load, which depends only on the mass per unit width.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr Real kL0 = 0.057, kH0 = 0.114, kG = 9.81, kRho = 997.5;

// Front position L = x_front / l0 at T = 2 (coarse grid: 0.0095 m cells, 2 particles per cell).
Real FrontAtT2(const std::string& bulk_modulus) {
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"),
                                {"grid.cell_size=0.0095", "bodies.0.particles_per_cell=2",
                                 "materials.water.bulk_modulus=" + bulk_modulus});
  const Real t_unit = 1 / std::sqrt(kH0 * kG / (kL0 * kL0));
  Real front = 0;
  testing::RunUntil(scene, 2 * t_unit, [&](const State&, const StepReport&) {});
  for (const Vec3& x : scene.state.particles.x) front = std::max(front, x.x());
  return (front + 0.5 * scene.model.dx / 2) / kL0;
}

TEST(DamBreakTest, FrontDoesNotDependOnTheReducedBulkModulus) {
  // Spec B1 [REC]: the result must not change when the reduced K is doubled (Mach 0.034 -> 0.024).
  const Real a = FrontAtT2("2.0e6"), b = FrontAtT2("4.0e6");
  std::printf("dam break front at T = 2: L = %.4f (K = 2e6 Pa), %.4f (K = 4e6 Pa), change %.2f %%\n",
              a, b, 100 * (b - a) / a);
  EXPECT_NEAR(a, b, 0.03 * a);
}

TEST(DamBreakTest, FrontAdvancesBelowTheRitterBound) {
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"));
  const Real spacing = scene.model.dx / 3;  // particles_per_cell: 3
  const Real t_unit = 1 / std::sqrt(kH0 * kG / (kL0 * kL0));  // T = t sqrt(h0 g / l0^2)
  Real last_L = 1, L_at_1 = 0, L_at_2 = 0, worst_ritter = 0;
  testing::RunUntil(scene, 2.5 * t_unit, [&](const State& s, const StepReport&) {
    Real front = 0;
    for (const Vec3& x : s.particles.x) front = std::max(front, x.x());
    const Real L = (front + 0.5 * spacing) / kL0, T = s.time / t_unit;
    EXPECT_LT(L, 1 + 2 * T + 1e-9) << "T = " << T;
    EXPECT_GE(L, last_L - 0.5 * spacing / kL0) << "the front moved back at T = " << T;
    worst_ritter = std::max(worst_ritter, L / (1 + 2 * T));
    last_L = std::max(last_L, L);
    if (L_at_1 == 0 && T >= 1) L_at_1 = L;
    if (L_at_2 == 0 && T >= 2) L_at_2 = L;
  });
  std::printf("dam break h0/l0 = 2: front L = %.3f at T = 1, %.3f at T = 2, %.3f at T = 2.5 "
              "(Ritter 1 + 2T: 3, 5, 6); max L / (1 + 2T) = %.3f\n",
              L_at_1, L_at_2, last_L, worst_ritter);
  EXPECT_GT(L_at_2, 2.0);  // the water has run more than one column width along the floor
}

TEST(DamBreakTest, SettledWaterCarriesItsWeightOnTheFloor) {
  // The dam break in a box W = 2 l0 wide (coarser: 0.0095 m cells, 2 particles per cell).
  const Real W = 2 * kL0, h = kH0 * kL0 / W;
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"),
                                {"domain.max=[0.114, 0.228]", "grid.cell_size=0.0095",
                                 "bodies.0.particles_per_cell=2"});
  const Real t_end = 2.0, t_avg = 1.5;
  Real floor = 0, pressure_bottom = 0, depth_bottom = 0;
  int samples = 0;
  testing::RunUntil(scene, t_end, [&](const State& s, const StepReport& r) {
    if (s.time < t_avg) return;
    floor += -r.walls.force[int(Face::kYMin)].y();
    ++samples;
  });
  floor /= samples;
  // Particle pressures (reported, not gated): without anti-locking (seed ch. 4, required for
  // fluids per spec §2.3) they alternate layer by layer about the hydrostatic profile.
  const Particles& P = scene.state.particles;
  int bottom = 0;
  Real pressure_mean = 0, depth_mean = 0;
  for (size_t p = 0; p < P.size(); ++p) {
    pressure_mean += -P.stress[p].trace() / 3 / Real(P.size());
    depth_mean += (h - P.x[p].y()) / Real(P.size());
    if (P.x[p].y() < scene.model.dx) {
      pressure_bottom += -P.stress[p].trace() / 3;
      depth_bottom += h - P.x[p].y();
      ++bottom;
    }
  }
  pressure_bottom /= bottom;
  depth_bottom /= bottom;
  const Real expected = kRho * kG * h;
  Real vmax = 0;
  for (const Vec3& v : P.v) vmax = std::max(vmax, v.norm());
  std::printf("settled dam break (W = %.3f m, h = %.4f m): mean base pressure %.2f Pa vs rho g h "
              "= %.2f Pa (error %.3f %%); particle pressure: bottom layer %.2f Pa vs rho g d = %.2f "
              "Pa, all particles %.2f Pa vs %.2f Pa; max |v| at end %.3g m/s\n",
              W, h, floor / W, expected, 100 * (floor / W - expected) / expected, pressure_bottom,
              kRho * kG * depth_bottom, pressure_mean, kRho * kG * depth_mean, vmax);
  EXPECT_NEAR(floor / W, expected, 0.02 * expected);
}

// Cell-based volumetric anti-locking on quadratic B-splines (docs/antilocking.md): the shipped
// dam break once blew up with it (floor reaction 1388 N at 0.25 s, 22x the weight); since
// remeasured on 2026-12-04 it stays bounded. Gate: the floor force never exceeds 4x the weight
// and carries it within [0.7, 1.5] on average over 0.15-0.3 s (the collapsing column still
// decelerates on the floor: node-based and cell-based both read 1.12 there).
TEST(DamBreakTest, CellBasedAntiLockingStaysBoundedOnBSplines) {
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"),
                                {"materials.water.antilocking={method: cell}", "time.end=0.3"});
  const Real weight = kRho * kG * kL0 * kH0;  // per metre [N/m]
  Real peak = 0, sum = 0;
  int n = 0;
  testing::RunUntil(scene, 0.3, [&](const State& s, const StepReport& r) {
    const Real f = -r.walls.force[int(Face::kYMin)].y();
    peak = std::max(peak, std::abs(f));
    if (s.time >= 0.15) sum += f, ++n;
  });
  std::printf("dam break, cell-based anti-locking, to 0.3 s: floor peak %.1f N/m (%.2f x weight "
              "%.1f N/m), mean over 0.15-0.3 s %.3f x weight\n", peak, peak / weight, weight,
              sum / n / weight);
  EXPECT_LT(peak, 4 * weight);
  EXPECT_GT(sum / n, 0.7 * weight);
  EXPECT_LT(sum / n, 1.5 * weight);
}

}  // namespace
}  // namespace surge

// 1-D elastic bar vibration (shared/VALIDATION.md): fixed at x = 0, free at x = L, initial
// velocity v0 sin(beta x). Closed form v = v0 sin(beta x) cos(omega t), omega = beta sqrt(E/rho),
// beta = pi/(2L): L = 25, E = 100, rho = 1 -> T = 10 s. Gate: period error < 0.5 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "support/run_scene.h"

namespace surge {
namespace {

Real MeasureBarPeriod(const std::vector<std::string>& overrides, Real* energy_drift,
                      Real* work_mismatch = nullptr) {
  LoadedScene scene = LoadScene(testing::ScenePath("elastic_bar_1d.yaml"), overrides);
  const Real L = 25.0, v0 = 0.01;
  const Real beta = std::numbers::pi / (2 * L);
  Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p) P.v[p] = Vec3(v0 * std::sin(beta * P.x[p].x()), 0, 0);
  const EnergyRecord e0 = ComputeEnergy(scene.model, scene.state);
  std::vector<Real> t, momentum;
  Real max_drift = 0, max_mismatch = 0;
  testing::RunUntil(scene, 25.0, [&](const State& s, const StepReport& r) {
    Real sum = 0;
    for (size_t p = 0; p < s.particles.size(); ++p) sum += s.particles.mass[p] * s.particles.v[p].x();
    t.push_back(s.time);
    momentum.push_back(sum);  // proportional to cos(omega t)
    const Real total = r.energy.kinetic + r.energy.strain;
    max_drift = std::max(max_drift, std::abs(total - e0.kinetic) / e0.kinetic);
    // The internal work sum V sigma : d dt equals the stored strain energy for an elastic bar.
    max_mismatch = std::max(max_mismatch, std::abs(r.energy.internal_work - r.energy.strain) / e0.kinetic);
  });
  if (energy_drift) *energy_drift = max_drift;
  if (work_mismatch) *work_mismatch = max_mismatch;
  return testing::PeriodFromCrossings(testing::ZeroCrossings(t, momentum));
}

TEST(ElasticBarTest, PeriodWithinHalfPercentOfClosedForm) {
  const Real exact = 4 * 25.0 / std::sqrt(100.0 / 1.0);  // 2 pi / omega = 4 L / c = 10 s
  Real drift = 0, mismatch = 0;
  const Real period = MeasureBarPeriod({}, &drift, &mismatch);
  RecordProperty("period", std::to_string(period));
  std::printf("elastic bar: period %.5f s (exact %.5f s, error %.3f %%), energy drift %.3f %%\n",
              period, exact, 100 * (period - exact) / exact, 100 * drift);
  EXPECT_NEAR(period, exact, 0.005 * exact) << "period " << period;
  // FLIP with a fixed end: the wall removes no energy from a standing wave (nodes at rest).
  EXPECT_LT(drift, 0.01);
  // The energy record's internal work (trapezoid on the stress power) against the elastic
  // energy 1/2 sigma : eps V: the largest difference over the run, relative to the initial
  // kinetic energy.
  std::printf("elastic bar: |internal work - strain energy| <= %.3g of the initial energy\n", mismatch);
  EXPECT_LT(mismatch, 0.01);
}

TEST(ElasticBarTest, PeriodConvergesForAllKernels) {
  const Real exact = 10.0;
  for (const char* shape : {"linear", "gimp", "cubic_bspline"}) {
    const Real period = MeasureBarPeriod({std::string("grid.shape_function=") + shape}, nullptr);
    std::printf("elastic bar, %s: period %.5f s (error %.3f %%)\n", shape, period,
                100 * (period - exact) / exact);
    EXPECT_NEAR(period, exact, 0.01 * exact) << shape << ": period " << period;
  }
}

// The clamped end with B-splines (docs/walls.md, "Folded mirror"): the quadratic and cubic
// B-splines reach the ghost nodes beyond the no-slip wall at x = 0. Folding each ghost's mass and
// momentum into its mirror node (domain.ghost_nodes: mirror, the default) is the reflection method
// for a Dirichlet condition, and the period converges at second order, as it does for a free-free
// bar with no wall at all (measured 2.0 for linear, quadratic and cubic). Overwriting only the
// ghost's velocity (mirror_velocity, the behaviour before 2026-12-03) loses the ghost's share of
// the internal force: first order, the bar about 0.15 h too long.
// Measured (h = 0.5 -> 0.25 m, first-mode start): see the printed lines; order mirror ~2.0,
// mirror_velocity ~1.0.
TEST(ElasticBarTest, ClampedEndConvergesAtSecondOrderWithBSplines) {
  const Real exact = 10.0;
  for (const char* shape : {"quadratic_bspline", "cubic_bspline"}) {
    Real order[2] = {0, 0};
    const char* ghosts[2] = {"mirror", "mirror_velocity"};
    for (int g = 0; g < 2; ++g) {
      Real error[2] = {0, 0};
      const Real h[2] = {0.5, 0.25};
      for (int level = 0; level < 2; ++level) {
        const Real period = MeasureBarPeriod({std::string("grid.shape_function=") + shape,
                                              "grid.cell_size=" + std::to_string(h[level]),
                                              std::string("domain.ghost_nodes=") + ghosts[g]},
                                             nullptr);
        error[level] = std::abs(period - exact) / exact;
      }
      order[g] = std::log2(error[0] / error[1]);
      std::printf("elastic bar, %s, ghost_nodes %s: error %.3e (h 0.5) -> %.3e (h 0.25), order %.2f\n",
                  shape, ghosts[g], error[0], error[1], order[g]);
      if (g == 0) {
        EXPECT_LT(error[1], 2e-4) << shape;
      }
    }
    EXPECT_GT(order[0], 1.7) << shape << ": the folded mirror converges at second order";
    EXPECT_LT(order[1], 1.4) << shape << ": the velocity-only mirror is first order (the defect)";
  }
}

}  // namespace
}  // namespace surge

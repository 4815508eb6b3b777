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

Real MeasureBarPeriod(const std::vector<std::string>& overrides, Real* energy_drift) {
  LoadedScene scene = LoadScene(testing::ScenePath("elastic_bar_1d.yaml"), overrides);
  const Real L = 25.0, v0 = 0.01;
  const Real beta = std::numbers::pi / (2 * L);
  Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p) P.v[p] = Vec3(v0 * std::sin(beta * P.x[p].x()), 0, 0);
  const EnergyRecord e0 = ComputeEnergy(scene.model, scene.state);
  std::vector<Real> t, momentum;
  Real max_drift = 0;
  testing::RunUntil(scene, 25.0, [&](const State& s, const StepReport& r) {
    Real sum = 0;
    for (size_t p = 0; p < s.particles.size(); ++p) sum += s.particles.mass[p] * s.particles.v[p].x();
    t.push_back(s.time);
    momentum.push_back(sum);  // proportional to cos(omega t)
    const Real total = r.energy.kinetic + r.energy.strain;
    max_drift = std::max(max_drift, std::abs(total - e0.kinetic) / e0.kinetic);
  });
  if (energy_drift) *energy_drift = max_drift;
  return testing::PeriodFromCrossings(testing::ZeroCrossings(t, momentum));
}

TEST(ElasticBarTest, PeriodWithinHalfPercentOfClosedForm) {
  const Real exact = 4 * 25.0 / std::sqrt(100.0 / 1.0);  // 2 pi / omega = 4 L / c = 10 s
  Real drift = 0;
  const Real period = MeasureBarPeriod({}, &drift);
  RecordProperty("period", std::to_string(period));
  std::printf("elastic bar: period %.5f s (exact %.5f s, error %.3f %%), energy drift %.3f %%\n",
              period, exact, 100 * (period - exact) / exact, 100 * drift);
  EXPECT_NEAR(period, exact, 0.005 * exact) << "period " << period;
  // FLIP with a fixed end: the wall removes no energy from a standing wave (nodes at rest).
  EXPECT_LT(drift, 0.01);
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

}  // namespace
}  // namespace surge

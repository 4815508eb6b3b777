// Cantilever beam, first mode (Mast 2013 §6.2; shared/VALIDATION.md): L = 10 m, d = 1 m, plane
// strain, clamped at x = 0, started with the first-mode velocity. Reference: Euler-Bernoulli
// omega_1 = (beta_1 L)^2 sqrt(E' I / (rho A L^4)), beta_1 L = 1.875104, E' = E / (1 - nu^2)
// (spec seed-validation-cases.md §3.4). Gate: first frequency within 2 %.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/run_scene.h"

namespace surge {
namespace {

// Mode shape phi(x) = cosh bx - cos bx - s (sinh bx - sin bx), s = 0.734096 (spec §3.4).
Real ModeShape(Real x, Real L) {
  const Real b = 1.875104 / L, s = 0.734096;
  return std::cosh(b * x) - std::cos(b * x) - s * (std::sinh(b * x) - std::sin(b * x));
}

TEST(CantileverTest, FirstFrequencyWithinTwoPercentOfEulerBernoulli) {
  LoadedScene scene = LoadScene(testing::ScenePath("cantilever_2d.yaml"), {"gravity=[0, 0]"});
  const auto& params = std::get<LinearElasticParams>(scene.model.materials[0].params);
  const Real K = params.bulk_modulus, G = params.shear_modulus, rho = scene.model.materials[0].density;
  const Real E = 9 * K * G / (3 * K + G);
  const Real nu = (3 * K - 2 * G) / (2 * (3 * K + G));
  const Real E_plane = E / (1 - nu * nu);
  const Real L = 10.0, d = 1.0;
  const Real I = d * d * d / 12, A = d;
  const Real omega = 1.875104 * 1.875104 * std::sqrt(E_plane * I / (rho * A * std::pow(L, 4)));
  const Real period_eb = 2 * M_PI / omega;

  // First-mode velocity with a tip speed giving a tip amplitude of d/200 (small deformation).
  const Real v_tip = omega * d / 200;
  Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p)
    P.v[p] = Vec3(0, v_tip * ModeShape(P.x[p].x(), L) / ModeShape(L, L), 0);

  std::vector<Real> t, tip;
  testing::RunUntil(scene, 1.3 * period_eb, [&](const State& s, const StepReport&) {
    Real sum = 0, mass = 0;
    for (size_t p = 0; p < s.particles.size(); ++p)
      if (s.particles.x[p].x() > L - 0.5) {
        sum += s.particles.mass[p] * s.particles.v[p].y();
        mass += s.particles.mass[p];
      }
    t.push_back(s.time);
    tip.push_back(sum / mass);
  });
  const auto crossings = testing::ZeroCrossings(t, tip);
  ASSERT_GE(crossings.size(), 2u);
  const Real period = testing::PeriodFromCrossings(crossings);
  RecordProperty("period_ratio", std::to_string(period / period_eb));
  std::printf("cantilever: MPM period %.5f s, Euler-Bernoulli %.5f s, ratio %.4f\n", period, period_eb,
              period / period_eb);
  EXPECT_NEAR(period / period_eb, 1.0, 0.02)
      << "MPM period " << period << " s, Euler-Bernoulli " << period_eb << " s";
}

}  // namespace
}  // namespace surge

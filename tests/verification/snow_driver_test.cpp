// Dense snow (cohesive modified Cam-clay, Gaume et al. 2018; materials/snow.h) at one material
// point (materials/material_driver.h) and in an engine run of scenes/snow_slab_3d.yaml.
//  - every plastic return lands on the updated yield surface (1e-8 relative to its terms);
//  - rigid rotations leave the stress invariants and the history unchanged;
//  - isotropic compaction follows the closed form of the sinh hardening law;
//  - hydrostatic tension yields at p = -beta p0, then softens to zero strength (cohesion loss);
//  - shear at constant p ends at the critical state q/p = M (1+beta)/((1-beta) sqrt(1+2 beta)),
//    compacting for p > p_cs and dilating for p < p_cs;
//  - a slab on a 35 deg slope with a Coulomb floor (mu = 0.2) stays put when cohesive (dry dense
//    snow) and flows when its cohesion and compressive strength are small.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "materials/material_driver.h"
#include "materials/snow.h"
#include "support/run_scene.h"
#include "support/random_paths.h"

namespace surge {
namespace {

// Parameter sets of docs/materials.md ("Dense snow"): E, nu -> K, G.
SnowParams FromYoungs(Real E, Real nu, Real M, Real beta, Real xi, Real p0) {
  return SnowParams{E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu)), M, beta, xi, p0};
}
SnowParams DrySnow() { return FromYoungs(3e6, 0.3, 1.2, 0.3, 0.5, 3e3); }
SnowParams WetSnow() { return FromYoungs(1e6, 0.3, 1.0, 0.1, 0.5, 1.5e3); }

Material SnowMaterial(const SnowParams& p) { return Material{"snow", 300.0, p}; }

Mat3 Tau(const MaterialPoint& pt) {
  return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix();
}
Real MeanPressure(const Mat3& tau) { return -tau.trace() / 3; }  // p, compression positive
Real ShearStress(const Mat3& tau) { return std::sqrt(1.5) * Dev(tau).norm(); }  // q
History Hist(const MaterialPoint& pt) { return pt.particles.history.Get(0); }

using testing::RandomL;

class SnowDriverTest : public ::testing::TestWithParam<int> {
 protected:
  SnowParams Params() const { return GetParam() == 0 ? DrySnow() : WetSnow(); }
  const char* Name() const { return GetParam() == 0 ? "dry" : "wet"; }
};

// Random strain paths with alternating compaction and dilation phases: every step that changes
// the history ends on the surface of the updated p0; every other step ends inside it.
TEST_P(SnowDriverTest, EveryPlasticStepEndsOnTheUpdatedYieldSurface) {
  const SnowParams p = Params();
  MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p));
  std::mt19937_64 rng(42);
  const Real dt = 1e-3, rate = 0.6;  // strain increments up to 6e-4, ~ 0.5-1 yield strain
  int plastic = 0, compacting = 0, dilating = 0;
  Real worst = 0;
  for (int step = 0; step < 4000; ++step) {
    const History before = Hist(pt);
    const Real bias = (step % 800 < 400 ? -0.3 : 0.3) * rate;  // volumetric phases
    StepMaterialPoint(pt, RandomL(rng, rate) + bias * Mat3::Identity(), dt);
    const History& h = Hist(pt);
    const Mat3 tau = Tau(pt);
    const Real y = SnowYieldFunction(p, tau, h), scale = SnowYieldScale(p, tau, h);
    ASSERT_TRUE(std::isfinite(y)) << "step " << step;
    if (h[kSnowPlasticStrain] != before[kSnowPlasticStrain] ||
        h[kSnowVolumetricPlastic] != before[kSnowVolumetricPlastic]) {
      ++plastic;
      compacting += h[kSnowVolumetricPlastic] < before[kSnowVolumetricPlastic];
      dilating += h[kSnowVolumetricPlastic] > before[kSnowVolumetricPlastic];
      if (scale > 0) worst = std::max(worst, std::abs(y) / scale);
      ASSERT_LE(std::abs(y), 1e-8 * scale) << "step " << step;
      ASSERT_EQ(h[kSnowConsolidation], SnowConsolidationPressure(p, h[kSnowVolumetricPlastic]));
    } else {
      ASSERT_LE(y, 1e-8 * scale) << "elastic step " << step << " outside the yield surface";
    }
  }
  std::printf("snow %s: %d plastic steps of 4000 (%d compacting, %d dilating), max |y|/scale = "
              "%.2e, final p0 = %.1f Pa, eps_q^p = %.4f\n",
              Name(), plastic, compacting, dilating, worst, Hist(pt)[kSnowConsolidation],
              Hist(pt)[kSnowPlasticStrain]);
  EXPECT_GT(plastic, 1000);
  EXPECT_GT(compacting, 100);
  EXPECT_GT(dilating, 100);
}

TEST_P(SnowDriverTest, RigidRotationLeavesInvariantsUnchanged) {
  const SnowParams p = Params();
  MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p));
  std::mt19937_64 rng(7);
  const Real dt = 1e-3;
  for (int step = 0; step < 300; ++step)
    StepMaterialPoint(pt, RandomL(rng, 0.6) - 0.2 * Mat3::Identity(), dt);
  ASSERT_GT(Hist(pt)[kSnowPlasticStrain], 0) << "the point must be plastic";

  std::uniform_real_distribution<Real> angle(-3.0, 3.0);
  Real worst = 0;
  for (int r = 0; r < 20; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const History h0 = Hist(pt);
    const Vec3 axis = Vec3(angle(rng), angle(rng), angle(rng)).normalized();
    const Mat3 R = Eigen::AngleAxis<Real>(angle(rng), axis).toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / dt, dt);  // f = I + dt L = R exactly
    const Mat3 sigma1 = pt.particles.stress[0].matrix();
    const Real scale = sigma0.norm();
    EXPECT_NEAR(sigma1.trace(), sigma0.trace(), 1e-10 * scale);
    EXPECT_NEAR(Dev(sigma1).norm(), Dev(sigma0).norm(), 1e-10 * scale);
    EXPECT_NEAR(Dev(sigma1).determinant(), Dev(sigma0).determinant(), 1e-10 * scale * scale * scale);
    EXPECT_LE((sigma1 - R * sigma0 * R.transpose()).norm(), 1e-10 * scale);
    // The point sits on the surface: round-off may make the trial y ~ +1e-16 and trigger a
    // return of that size.
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(Hist(pt)[k], h0[k], 1e-12 * std::abs(h0[k])) << "history slot " << k;
    worst = std::max(worst, (sigma1 - R * sigma0 * R.transpose()).norm() / scale);
  }
  std::printf("snow %s: rigid rotations, max |sigma - R sigma0 R^T| / |sigma0| = %.2e\n", Name(),
              worst);
}

// Isotropic compression from the stress-free state: elastic until p = p0_init, then on the cap
// tip p = p0(alpha) = K sinh(xi a), a = -alpha, while p = -K (ln J - (alpha - alpha_0)) (Hencky,
// ln J = ln J^e + ln J^p). Eliminating alpha: -ln J = p/K + a(p) - a_0 with a(p) = asinh(p/K)/xi,
// exact at any strain (log strains of a coaxial path add).
TEST_P(SnowDriverTest, IsotropicCompactionFollowsTheSinhHardeningLaw) {
  const SnowParams p = Params();
  const Real K = p.bulk_modulus, xi = p.hardening_factor;
  MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p));
  const Real a0 = std::asinh(p.consolidation_pressure / K) / xi;
  ASSERT_NEAR(-Hist(pt)[kSnowVolumetricPlastic], a0, 1e-15);
  const Real dt = 1e-3, rate = -0.1;  // ln J = 3 ln(1 - 1e-4) per step, -0.3 after 1000 steps
  Real worst = 0, first_yield_p = -1, lnJ_before = 0, d_lnJ = 0;
  int plastic = 0;
  for (int step = 0; step < 1000; ++step) {
    const Real alpha_before = Hist(pt)[kSnowVolumetricPlastic];
    StepMaterialPoint(pt, rate * Mat3::Identity(), dt);
    const Mat3 tau = Tau(pt);
    const Real pm = MeanPressure(tau), lnJ = std::log(pt.particles.F[0].determinant());
    d_lnJ = lnJ - lnJ_before;
    lnJ_before = lnJ;
    if (Hist(pt)[kSnowVolumetricPlastic] == alpha_before) {
      ASSERT_NEAR(pm, -K * lnJ, 1e-12 * K);  // elastic: p = -K ln J
      continue;
    }
    if (plastic++ == 0) first_yield_p = -K * (lnJ - d_lnJ);  // p at the last elastic step
    const Real a = std::asinh(pm / K) / xi;
    const Real predicted = pm / K + a - a0;  // -ln J
    worst = std::max(worst, std::abs(-lnJ - predicted) / std::abs(lnJ));
    ASSERT_NEAR(-lnJ, predicted, 1e-10 * std::abs(lnJ)) << "step " << step;
    ASSERT_NEAR(Hist(pt)[kSnowConsolidation], pm, 1e-10 * pm);  // on the tip: p = p0
    ASSERT_LE(ShearStress(tau), 1e-9 * pm);
  }
  const Real p_end = MeanPressure(Tau(pt));
  std::printf("snow %s: isotropic compaction to ln J = %.3f: p = %.1f kPa (p0 from %.1f to %.1f "
              "kPa), first yield between p = %.1f and %.1f Pa, max rel. error vs closed form "
              "%.2e\n",
              Name(), std::log(pt.particles.F[0].determinant()), p_end / 1e3,
              p.consolidation_pressure / 1e3, Hist(pt)[kSnowConsolidation] / 1e3, first_yield_p,
              first_yield_p - K * d_lnJ, worst);
  EXPECT_GT(plastic, 900);
  EXPECT_LE(first_yield_p, p.consolidation_pressure);  // elastic up to p0_init
  EXPECT_GE(first_yield_p - K * d_lnJ, p.consolidation_pressure);  // trial p of the first return
  EXPECT_GT(p_end, 10 * p.consolidation_pressure);  // compaction hardens
}

// Isotropic extension: elastic until p = -beta p0_init (the tensile strength of the cap), then
// on the tension tip p = -beta p0(alpha) while alpha grows (dilation): p0 and the tensile
// strength soften to zero once alpha >= 0 (cohesion lost), and the stress vanishes.
TEST_P(SnowDriverTest, HydrostaticTensionYieldsAtMinusBetaP0ThenLosesCohesion) {
  const SnowParams p = Params();
  const Real beta = p.cohesion_ratio, p0i = p.consolidation_pressure;
  MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p));
  const Real dt = 1e-4, rate = 0.1;  // ln J increments 3e-5 (beta p0_init / K ~ 2e-4-4e-4)
  const Real a0 = -Hist(pt)[kSnowVolumetricPlastic];
  Real min_p = 0, first_plastic_p = 0, worst = 0;
  int plastic = 0;
  Real last_p0 = p0i;
  for (int step = 0; step < 8000; ++step) {
    const Real alpha_before = Hist(pt)[kSnowVolumetricPlastic];
    StepMaterialPoint(pt, rate * Mat3::Identity(), dt);
    const Real pm = MeanPressure(Tau(pt)), lnJ = std::log(pt.particles.F[0].determinant());
    min_p = std::min(min_p, pm);
    if (Hist(pt)[kSnowVolumetricPlastic] == alpha_before) continue;
    if (plastic++ == 0) first_plastic_p = pm;
    const Real p0 = Hist(pt)[kSnowConsolidation];
    ASSERT_NEAR(pm, -beta * p0, 1e-10 * beta * p0i) << "step " << step;  // on the tension tip
    ASSERT_LE(p0, last_p0) << "softening must be monotone";
    last_p0 = p0;
    // Closed form of the tension branch: ln J = -p/K + alpha - alpha_0 with p = -beta K sinh(xi a),
    // a = max(-alpha, 0), alpha_0 = -a0.
    const Real a = std::max(-Hist(pt)[kSnowVolumetricPlastic], Real(0));
    const Real predicted = beta * std::sinh(p.hardening_factor * a) +
                           Hist(pt)[kSnowVolumetricPlastic] + a0;
    worst = std::max(worst, std::abs(lnJ - predicted) / lnJ);
    ASSERT_NEAR(lnJ, predicted, 1e-10 * lnJ);
  }
  std::printf("snow %s: hydrostatic tension: min p = %.2f Pa vs -beta p0 = %.2f Pa; first "
              "plastic p = %.2f Pa; final p0 = %.3g Pa, |sigma| = %.3g Pa; closed-form error "
              "%.1e\n",
              Name(), min_p, -beta * p0i, first_plastic_p, Hist(pt)[kSnowConsolidation],
              pt.particles.stress[0].matrix().norm(), worst);
  EXPECT_GE(min_p, -beta * p0i * (1 + 1e-12));  // never beyond the tensile strength
  EXPECT_LE(min_p, -beta * p0i * (1 - 1e-2));   // and it reaches it
  EXPECT_EQ(Hist(pt)[kSnowConsolidation], 0);   // ln J = 0.24 > a0 + elastic: cohesion gone
  EXPECT_LE(pt.particles.stress[0].matrix().norm(), 1e-12 * p0i);
}

// Simple shear at constant mean stress (xx, yy, zz stress-controlled, spec §2.10): the stress
// ratio tends to the critical state at the top of the ellipse, p = p_cs = (1 - beta) p0 / 2.
// Below p_cs ("dense", over-consolidated) the flow dilates and p0 softens; above it ("loose")
// the flow compacts and p0 hardens.
TEST_P(SnowDriverTest, ShearAtConstantPReachesTheCriticalState) {
  const SnowParams p = Params();
  const Real p_cs0 = 0.5 * (1 - p.cohesion_ratio) * p.consolidation_pressure;
  const Real ratio_cs = SnowCriticalStateRatio(p);
  for (const Real factor : {0.4, 1.8}) {  // p = factor x p_cs(p0_init)
    const Real pm = factor * p_cs0;
    MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p), -pm * Mat3::Identity());
    const Real alpha0 = Hist(pt)[kSnowVolumetricPlastic];
    MixedControl c;
    c.L(0, 1) = 1.0;  // simple shear rate [1/s]
    c.stress_controlled = {true, true, true, false, false, false};
    c.target = -pm * Mat3::Identity();
    const Real dt = 2e-4;
    int wrong_sign = 0, plastic = 0, outside = 0;
    Real peak_ratio = 0;
    for (int step = 0; step < 3000; ++step) {  // shear strain 0.6
      const Real alpha_before = Hist(pt)[kSnowVolumetricPlastic];
      ASSERT_GE(MixedControlStep(pt, c, dt, 1e-9 * pm), 0) << "step " << step;
      const Mat3 tau = Tau(pt);
      const Real d_alpha = Hist(pt)[kSnowVolumetricPlastic] - alpha_before;
      const Real p_cs = 0.5 * (1 - p.cohesion_ratio) * Hist(pt)[kSnowConsolidation];
      peak_ratio = std::max(peak_ratio, ShearStress(tau) / MeanPressure(tau));
      // Never outside the updated surface, the critical state (top of the ellipse) included.
      if (SnowYieldFunction(p, tau, Hist(pt)) > 1e-9 * SnowYieldScale(p, tau, Hist(pt))) ++outside;
      if (d_alpha != 0) {
        ++plastic;
        // d eps_v^p = -dgamma M^2 (2p - (1 - beta) p0): compaction above p_cs, dilation below.
        // At the critical state itself (|p - p_cs| at round-off) d_alpha is round-off too.
        const Real off = MeanPressure(tau) - p_cs;
        if (d_alpha * off > 0 && std::abs(off) > 1e-9 * p_cs) ++wrong_sign;
      }
    }
    const Mat3 tau = Tau(pt);
    const Real ratio = ShearStress(tau) / MeanPressure(tau);
    const Real d_alpha = Hist(pt)[kSnowVolumetricPlastic] - alpha0;
    std::printf("snow %s: shear at p = %.2f p_cs: q/p = %.4f (critical state %.4f, peak %.4f), "
                "d eps_v^p = %+.4f, J = %.4f, p0 %.0f -> %.0f Pa, %d plastic steps\n",
                Name(), factor, ratio, ratio_cs, peak_ratio, d_alpha,
                pt.particles.F[0].determinant(), p.consolidation_pressure,
                Hist(pt)[kSnowConsolidation], plastic);
    EXPECT_NEAR(ratio, ratio_cs, 0.01 * ratio_cs);
    EXPECT_NEAR(MeanPressure(pt.particles.stress[0].matrix()), pm, 1e-8 * pm);
    EXPECT_EQ(wrong_sign, 0);
    EXPECT_EQ(outside, 0);
    EXPECT_GT(plastic, 1000);
    if (factor < 1) {
      EXPECT_GT(d_alpha, 0) << "dense side dilates";
      EXPECT_GT(pt.particles.F[0].determinant(), 1);
      EXPECT_LT(Hist(pt)[kSnowConsolidation], p.consolidation_pressure) << "and softens";
      EXPECT_GT(peak_ratio, 1.05 * ratio_cs) << "with a peak above the critical state";
    } else {
      EXPECT_LT(d_alpha, 0) << "loose side compacts";
      EXPECT_LT(pt.particles.F[0].determinant(), 1);
      EXPECT_GT(Hist(pt)[kSnowConsolidation], p.consolidation_pressure) << "and hardens";
    }
  }
}

// Geostatic start (InitialPlasticHistory): a stress inside the initial surface keeps p0_init; one
// outside it (deep, normally consolidated snow) raises p0 to the smallest ellipse through it. Either
// way the start is consistent: y <= 0 (= 0 in the second case) and a step with f = I reproduces
// the stress without a plastic return.
TEST_P(SnowDriverTest, GeostaticStartIsOnOrInsideTheSurface) {
  const SnowParams p = Params();
  for (const Real depth_stress : {0.3 * p.consolidation_pressure, 5 * p.consolidation_pressure}) {
    const Real k0 = 0.5;  // sigma_h = K0 sigma_v, compression negative
    const Mat3 sigma = -depth_stress * Vec3(k0, 1, k0).asDiagonal().toDenseMatrix();
    MaterialPoint pt = MakeMaterialPoint(SnowMaterial(p), sigma);
    const History h0 = Hist(pt);
    const Real y0 = SnowYieldFunction(p, sigma, h0), scale = SnowYieldScale(p, sigma, h0);
    EXPECT_LE(y0, 1e-12 * scale);
    EXPECT_EQ(h0[kSnowConsolidation], SnowConsolidationPressure(p, h0[kSnowVolumetricPlastic]));
    const bool outside = depth_stress > p.consolidation_pressure;  // p = 2/3 sigma_v > p0_init
    if (outside) {
      EXPECT_NEAR(y0, 0, 1e-12 * scale) << "raised p0 puts the stress on the surface";
      EXPECT_GT(h0[kSnowConsolidation], p.consolidation_pressure);
    } else {
      EXPECT_NEAR(h0[kSnowConsolidation], p.consolidation_pressure, 1e-12 * p.consolidation_pressure);
    }
    StepMaterialPoint(pt, Mat3::Zero(), 1e-3);
    const Real err = (pt.particles.stress[0].matrix() - sigma).norm() / sigma.norm();
    std::printf("snow %s: geostatic sigma_v = %.0f Pa (K0 = 0.5): p0 = %.0f Pa (%s), y/scale = "
                "%.1e, |sigma - sigma_0|/|sigma_0| after f = I: %.1e\n",
                Name(), depth_stress, h0[kSnowConsolidation], outside ? "raised" : "p0_init",
                y0 / scale, err);
    EXPECT_LE(err, 1e-12);
    EXPECT_NEAR(Hist(pt)[kSnowVolumetricPlastic], h0[kSnowVolumetricPlastic], 1e-15);
    EXPECT_LE(Hist(pt)[kSnowPlasticStrain], 1e-15);  // at most a round-off return
  }
}

INSTANTIATE_TEST_SUITE_P(DryAndWet, SnowDriverTest, ::testing::Values(0, 1));

// scenes/snow_slab_3d.yaml, coarser (dx = 0.1 m, 3 cells through the 0.3 m slab, a 0.2 m wide
// strip between slip walls) and to t = 1 s: mass-weighted mean downslope displacement of the slab
// and its largest equivalent plastic strain.
struct SlabRun {
  Real displacement;  // [m]
  Real max_plastic_strain;
  Real mean_speed;  // [m/s] at the end
};
SlabRun RunSlab(const std::vector<std::string>& material) {
  std::vector<std::string> overrides = {"grid.cell_size=0.1", "domain.max=[6, 1.2, 0.2]",
                                        "bodies.0.region.box.max=[3.3, 0.3, 0.2]"};
  overrides.insert(overrides.end(), material.begin(), material.end());
  LoadedScene scene = LoadScene(testing::ScenePath("snow_slab_3d.yaml"), overrides);
  const Particles& P = scene.state.particles;
  auto mean_x = [&] {
    Real m = 0, mx = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      m += P.mass[i];
      mx += P.mass[i] * P.x[i].x();
    }
    return mx / m;
  };
  const Real x0 = mean_x();
  testing::RunUntil(scene, 1.0, [](const State&, const StepReport&) {});
  SlabRun r{mean_x() - x0, 0, 0};
  Real m = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    r.max_plastic_strain = std::max(r.max_plastic_strain, P.history[i][kSnowPlasticStrain]);
    r.mean_speed += P.mass[i] * P.v[i].x();
    m += P.mass[i];
  }
  r.mean_speed /= m;
  return r;
}

// On a 35 deg slope with a bed friction mu = 0.8 > tan 35 deg, the wet slab (as-is: beta = 0.1,
// p0 = 1.5 kPa, M = 1) yields and flows; the dry dense slab (beta = 0.3, p0 = 3 kPa, M = 1.2,
// docs/materials.md) carries its weight elastically and stays put.
TEST(SnowSlabTest, WetSlabFlowsDownTheSlopeWhileTheCohesiveDrySlabStaysPut) {
  const SlabRun wet = RunSlab({});
  const SlabRun dry = RunSlab({"materials.snow.density=300", "materials.snow.youngs_modulus=3e6",
                               "materials.snow.critical_state_slope=1.2",
                               "materials.snow.cohesion_ratio=0.3",
                               "materials.snow.consolidation_pressure=3000"});
  std::printf("snow slab, 35 deg, mu = 0.8, t = 1 s: wet: mean displacement %.4f m, speed %.3f "
              "m/s, max eps_q^p %.3f; dry: %.5f m, %.4f m/s, max eps_q^p %.4f\n",
              wet.displacement, wet.mean_speed, wet.max_plastic_strain, dry.displacement,
              dry.mean_speed, dry.max_plastic_strain);
  EXPECT_GT(wet.displacement, 0.05);
  EXPECT_GT(wet.mean_speed, 0.1);
  EXPECT_LT(std::abs(dry.displacement), 0.005);
  EXPECT_LT(std::abs(dry.mean_speed), 0.01);
  EXPECT_GT(wet.displacement, 20 * std::abs(dry.displacement));
}

}  // namespace
}  // namespace surge

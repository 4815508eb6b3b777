// Modified Drucker-Prager (materials/modified_drucker_prager.h; Mast 2013 §3.6.3-3.6.4, spec
// §2.7) at one material point (materials/material_driver.h):
//  - every plastic return ends on the cone of the frozen (step-start) angle, |F| <= 1e-8 ||tau||;
//  - the stored angles follow the evolution laws (3.112)-(3.114) of the stored lambda;
//  - rigid rotations leave the invariants and the history unchanged (objectivity);
//  - plastic volume change d(ln J^p) = 3 varrho_G d lambda has the sign of psi_G, and is zero with
//    the dilation forced to 0;
//  - triaxial compression at a fixed angle (a1 = a4 = 0) reaches the Mohr-Coulomb compression
//    strength q_f = 6 sin(phi) / (3 - sin(phi)) (p' + c cot(phi)) (the cone (3.107) passes
//    through the MC compression vertices);
//  - hydrostatic tension returns to the apex: zero stress for c = 0;
//  - along a drained triaxial shearing path (a2 = 0) the mobilised strength q / p' follows the
//    frozen angle phi_F of each step, peaks at lambda* = 1/a3 + a4/a1 with phi_F = a0 +
//    (a1/a3) exp(-1 - a3 a4/a1) (spec §2.7 [DERIVED]) and softens to the critical angle a0.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

#include "materials/friction_angles.h"
#include "materials/material_driver.h"
#include "materials/modified_drucker_prager.h"
#include "support/random_paths.h"

namespace surge {
namespace {

// Seed §3.8 elastic pair (E = 75 MPa, nu = 0.33), Table 3.5 column i constants (a2 in 1/Pa).
ModifiedDruckerPragerParams SeedSand(Real cohesion = 0, bool zero_dilation = false) {
  const Real E = 75e6, nu = 0.33;
  ModifiedDruckerPragerParams p;
  p.bulk_modulus = E / (3 * (1 - 2 * nu));
  p.shear_modulus = E / (2 * (1 + nu));
  p.cohesion = cohesion;
  p.friction = FrictionCurve{20, 7750, 3.33e-7, 150, 20, 300};
  p.zero_dilation = zero_dilation;
  return p;
}
Material Sand(const ModifiedDruckerPragerParams& p) { return Material{"sand", 2000.0, p}; }
Mat3 Tau(const MaterialPoint& pt) { return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix(); }
using testing::RandomL;
// Plastic volumetric strain ln J^p = ln J - tr(eps_e), eps_e = 1/2 ln b^e.
Real PlasticVolume(const MaterialPoint& pt) {
  return std::log(pt.particles.F[0].determinant()) -
         0.5 * std::log(pt.particles.elastic_b[0].matrix().determinant());
}

TEST(ModifiedDruckerPragerTest, ReturnsLandOnTheFrozenConeAndAnglesFollowTheLaws) {
  for (const Real cohesion : {0.0, 20e3}) {
    const ModifiedDruckerPragerParams p = SeedSand(cohesion);
    MaterialPoint pt = MakeMaterialPoint(Sand(p), -150e3 * Mat3::Identity());
    std::mt19937_64 rng(11);
    int plastic = 0, apex = 0;
    Real worst = 0;
    for (int step = 0; step < 4000; ++step) {
      const History before = pt.particles.history.Get(0);
      // A shear in a fixed direction (reversed every 500 steps) plus random isochoric noise, and
      // a short hydrostatic stretch every 1000 steps to reach the apex.
      Mat3 L = RandomL(rng, 0.5);
      L -= L.trace() / 3.0 * Mat3::Identity();
      const Real sense = (step / 500) % 2 ? -1.0 : 1.0;
      L(0, 1) += sense * 2.0;
      L(1, 0) += sense * 2.0;
      if (step % 1000 >= 990) L = 20.0 * Mat3::Identity();
      StepMaterialPoint(pt, L, 1e-4);
      const History h = pt.particles.history.Get(0);
      if (h[kMdpLambda] == before[kMdpLambda]) continue;
      ++plastic;
      const Mat3 tau = Tau(pt);
      const Real scale = std::max(tau.norm(), 1.0);
      if (Dev(tau).norm() < 1e-9 * scale) {  // apex: I1 = -sigma_eff / varrho_F
        ++apex;
        continue;
      }
      const Real f = ModifiedDruckerPragerYield(p, tau, before);
      worst = std::max(worst, std::abs(f) / scale);
      ASSERT_LE(std::abs(f), 1e-8 * scale) << "step " << step;
      // (3.113)-(3.114), (3.112) of the stored lambda and the converged I1 (Cauchy).
      const Real I1 = pt.particles.stress[0].matrix().trace();
      EXPECT_NEAR(h[kMdpFriction], MobilisedFrictionDeg(p.friction, I1, h[kMdpLambda]), 1e-12);
      EXPECT_NEAR(h[kMdpCritical], CriticalFrictionDeg(p.friction, h[kMdpLambda]), 1e-12);
      EXPECT_NEAR(h[kMdpDilation], DilationAngleDeg(h[kMdpFriction], h[kMdpCritical]), 1e-12);
    }
    std::printf("modified DP c = %g: %d plastic steps (%d at the apex), max |F|/|tau| = %.2e, "
                "lambda = %.3f, phi_F = %.2f deg\n",
                cohesion, plastic, apex, worst, pt.particles.history[0][kMdpLambda],
                pt.particles.history[0][kMdpFriction]);
    EXPECT_GT(plastic - apex, 1000);
  }
}

TEST(ModifiedDruckerPragerTest, RigidRotationLeavesInvariantsAndHistoryUnchanged) {
  MaterialPoint pt = MakeMaterialPoint(Sand(SeedSand()), -150e3 * Mat3::Identity());
  std::mt19937_64 rng(5);
  for (int step = 0; step < 200; ++step) {
    Mat3 L = RandomL(rng, 2.0);
    L -= (L.trace() / 3.0 + 0.3) * Mat3::Identity();
    StepMaterialPoint(pt, L, 1e-4);
  }
  ASSERT_GT(pt.particles.history[0][kMdpLambda], 0);
  std::uniform_real_distribution<Real> u(-3.0, 3.0);
  for (int r = 0; r < 10; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const History h0 = pt.particles.history.Get(0);
    const Mat3 R =
        Eigen::AngleAxis<Real>(u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / 1e-4, 1e-4);  // f = R
    EXPECT_LE((pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm(), 1e-10 * sigma0.norm());
    for (int i = 0; i < kHistorySlots; ++i) EXPECT_EQ(pt.particles.history[0][i], h0[i]);
  }
}

TEST(ModifiedDruckerPragerTest, PlasticVolumeChangeHasTheSignOfTheDilationAngle) {
  // Table 3.5 i (dense): phi_F > phi_cs throughout at p = 150 kPa, so psi > 0: dilation. A loose
  // curve whose critical angle rises faster than the mobilised one (a5 > a3) gives psi < 0:
  // contraction (3.112). With the dilation forced to 0 the flow is isochoric.
  struct Case {
    const char* name;
    FrictionCurve curve;
    bool zero;
    int sign;  // expected sign of the plastic volume change
  };
  for (const Case& k : {Case{"dense (Table 3.5 i)", FrictionCurve{20, 7750, 3.33e-7, 150, 20, 300}, false, 1},
                        Case{"loose (a3 = 50, a5 = 300)", FrictionCurve{30, 0, 0, 50, 20, 300}, false, -1},
                        Case{"dense, zero dilation", FrictionCurve{20, 7750, 3.33e-7, 150, 20, 300}, true, 0}}) {
    ModifiedDruckerPragerParams p = SeedSand(0, k.zero);
    p.friction = k.curve;
    MaterialPoint pt = MakeMaterialPoint(Sand(p), -150e3 * Mat3::Identity());
    int contracting = 0, dilating = 0, plastic = 0;
    for (int step = 0; step < 400; ++step) {
      const Real psi = pt.particles.history[0][kMdpDilation];
      const Real lambda = pt.particles.history[0][kMdpLambda];
      const Real volume = PlasticVolume(pt);
      Mat3 L = Mat3::Zero();
      L(0, 1) = L(1, 0) = 0.5;  // simple shear rate 1 /s (no spin)
      StepMaterialPoint(pt, L, 1e-4);
      const Real dl = pt.particles.history[0][kMdpLambda] - lambda;
      const Real dv = PlasticVolume(pt) - volume;
      if (dl <= 0) continue;
      ++plastic;
      // A contracting (psi < 0) sand sheared at constant volume loses pressure until it reaches
      // the stress-free apex (static liquefaction); the apex return is two-surface, not (3.110).
      if (Dev(Tau(pt)).norm() <= 1e-9 * std::max(Tau(pt).norm(), 1.0)) continue;
      // d ln J^p = tr(dgamma g) = 3 varrho_G dgamma (3.108)-(3.110), varrho_G of the frozen psi.
      EXPECT_NEAR(dv, 3 * DruckerPragerSlope(Radians(psi)) * dl, 1e-9 * dl + 1e-13) << step;
      contracting += dv < -1e-12;
      dilating += dv > 1e-12;
    }
    std::printf("modified DP %s: %d plastic steps in shear, %d contracting, %d dilating\n", k.name,
                plastic, contracting, dilating);
    EXPECT_GT(plastic, 300);
    EXPECT_EQ(k.sign > 0 ? contracting : dilating, 0) << k.name;
    if (k.sign != 0) {
      EXPECT_GT(k.sign > 0 ? dilating : contracting, 0) << k.name;
    } else {
      EXPECT_EQ(contracting + dilating, 0) << k.name;
    }
  }
}

TEST(ModifiedDruckerPragerTest, TriaxialCompressionReachesTheMohrCoulombStrength) {
  for (const Real c : {0.0, 30e3}) {
    ModifiedDruckerPragerParams p = SeedSand(c, true);
    p.friction = FrictionCurve{30, 0, 0, 0, 0, 0};  // constant 30 deg
    MaterialPoint pt = MakeMaterialPoint(Sand(p), -100e3 * Mat3::Identity());
    MixedControl m;
    m.stress_controlled = {false, true, true, true, true, true};
    m.target = -100e3 * Mat3::Identity();
    m.target(0, 0) = 0;
    for (int step = 0; step < 300; ++step) {
      m.L(0, 0) = -1.0;  // axial compression, 1e-4 per step
      ASSERT_GE(MixedControlStep(pt, m, 1e-4, 1e-6), 0) << "step " << step;
    }
    // Kirchhoff stresses (the model's strength is on tau): q = |tau_11 - tau_22|, p' = -I1/3.
    const Mat3 tau = Tau(pt);
    const Real q = tau(1, 1) - tau(0, 0), pc = -tau.trace() / 3;
    const Real s = std::sin(Radians(30));
    const Real qf = 6 * s / (3 - s) * (pc + c / std::tan(Radians(30)));
    std::printf("modified DP triaxial compression c = %g: q = %.6g Pa, MC q_f = %.6g Pa\n", c, q, qf);
    EXPECT_NEAR(q, qf, 1e-6 * qf);
  }
}

TEST(ModifiedDruckerPragerTest, HydrostaticTensionReturnsToTheApex) {
  // Apex I1 = -sigma_Y^Eff / varrho_F = 3 c cot(phi) (3.107), spec §9 erratum 4: the mean stress
  // is c cot(phi), as for Mohr-Coulomb; for c = 0 the apex is the stress-free state.
  for (const Real c : {0.0, 10e3}) {
    ModifiedDruckerPragerParams p = SeedSand(c);
    p.friction = FrictionCurve{30, 0, 0, 0, 0, 0};
    MaterialPoint pt = MakeMaterialPoint(Sand(p), Mat3::Zero());
    StepMaterialPoint(pt, 0.1 * Mat3::Identity(), 1e-1);  // 1 % stretch per axis
    const Mat3 tau = Tau(pt);
    const Real mean = c / std::tan(Radians(30));
    EXPECT_LE((tau - mean * Mat3::Identity()).norm(), 1e-9 * std::max(mean, 1.0)) << "c = " << c;
    EXPECT_GT(PlasticVolume(pt), 0.02) << "the stretch beyond the apex is plastic";
  }
  // Zero mobilised angle (Table 3.5 i at lambda = 0 in tension): no apex, no division by zero.
  MaterialPoint zero = MakeMaterialPoint(Sand(SeedSand(0)), Mat3::Zero());
  StepMaterialPoint(zero, 0.1 * Mat3::Identity(), 1e-1);
  EXPECT_TRUE(zero.particles.stress[0].matrix().allFinite());
}

TEST(ModifiedDruckerPragerTest, ShearingPathPeaksAtLambdaStarAndEndsAtA0) {
  // a2 = 0: phi_F = a0 + (a1 lambda - a4) exp(-a3 lambda) (3.113) peaks where d phi_F / d lambda
  // = 0, lambda* = 1/a3 + a4/a1 = 0.015, phi_F* = 30 + 20 exp(-1.5) = 34.46 deg.
  ModifiedDruckerPragerParams p = SeedSand(0, true);
  p.friction = FrictionCurve{30, 2000, 0, 100, 10, 50};
  const FrictionCurve& a = p.friction;
  const Real lambda_star = 1 / a.a3 + a.a4 / a.a1;
  const Real phi_star = a.a0 + a.a1 / a.a3 * std::exp(-1 - a.a3 * a.a4 / a.a1);
  MaterialPoint pt = MakeMaterialPoint(Sand(p), -100e3 * Mat3::Identity());
  History h0;
  InitialPlasticHistory(p, pt.particles.stress[0].matrix(), h0);
  pt.particles.history.Set(0, h0);
  EXPECT_NEAR(h0[kMdpFriction], a.a0 - a.a4, 1e-12) << "geostatic start: phi_F(I1, 0)";
  MixedControl m;
  m.stress_controlled = {false, true, true, true, true, true};
  m.target = -100e3 * Mat3::Identity();
  m.target(0, 0) = 0;
  m.L(0, 0) = -1.0;  // axial compression, 5e-4 per step
  Real phi_peak = 0, lambda_peak = 0, worst_ratio = 0, dlambda_max = 0;
  for (int step = 0; step < 800; ++step) {
    const History before = pt.particles.history.Get(0);
    ASSERT_GE(MixedControlStep(pt, m, 5e-4, 1e-6), 0) << "step " << step;
    const History h = pt.particles.history.Get(0);
    if (h[kMdpLambda] == before[kMdpLambda]) continue;
    dlambda_max = std::max(dlambda_max, h[kMdpLambda] - before[kMdpLambda]);
    // Triaxial compression on the cone of the frozen angle: q = 6 sin phi / (3 - sin phi) p'.
    const Mat3 tau = Tau(pt);
    const Real q = tau(1, 1) - tau(0, 0), pc = -tau.trace() / 3;
    const Real s = std::sin(Radians(before[kMdpFriction]));
    worst_ratio = std::max(worst_ratio, std::abs(q / pc - 6 * s / (3 - s)) / (6 * s / (3 - s)));
    if (h[kMdpFriction] > phi_peak) {
      phi_peak = h[kMdpFriction];
      lambda_peak = h[kMdpLambda];
    }
  }
  const History h = pt.particles.history.Get(0);
  std::printf("modified DP shearing path: peak phi_F %.4f deg at lambda %.5f (law: %.4f deg at "
              "lambda* %.5f, step dlambda <= %.2e); end lambda %.3f phi_F %.6f deg (a0 %g), "
              "phi_cs %.6f; max |q/p' - MC ratio of the frozen angle| %.2e\n",
              phi_peak, lambda_peak, phi_star, lambda_star, dlambda_max, h[kMdpLambda],
              h[kMdpFriction], a.a0, h[kMdpCritical], worst_ratio);
  EXPECT_LE(worst_ratio, 1e-6);
  EXPECT_NEAR(lambda_peak, lambda_star, dlambda_max);
  EXPECT_LE(phi_peak, phi_star + 1e-12);
  // The sampled peak lies within one step of lambda*: below phi_F* by at most
  // 1/2 |phi_F''(lambda*)| dlambda^2, phi_F''(lambda*) = -a1 a3 exp(-a3 lambda*).
  const Real curvature = a.a1 * a.a3 * std::exp(-a.a3 * lambda_star);
  EXPECT_GE(phi_peak, phi_star - 0.5 * curvature * dlambda_max * dlambda_max);
  EXPECT_GT(h[kMdpLambda], 0.3);
  EXPECT_NEAR(h[kMdpFriction], a.a0, 1e-6);
  EXPECT_NEAR(h[kMdpCritical], a.a0, 1e-6);
}

}  // namespace
}  // namespace surge

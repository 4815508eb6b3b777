// Smooth-cap Drucker-Prager (materials/smooth_cap_drucker_prager.h; Mast 2013 §3.6.2, spec §2.6)
// through the principal-space return and at one material point (materials/material_driver.h):
//  - random trial stresses in every region: the return lands on the surface, |F| <= 1e-8 scale,
//    and every region (cone, cap, tangent ring) is exercised; the cap and cone meet smoothly
//    (F1 = F2 = 0 at the tangent ring);
//  - the cone return's plastic flow has the volume change 3 varrho_G dgamma (sign of the
//    associativity), the cap's is dilative (associated flow in tension);
//  - rigid rotations leave the stress unchanged up to the rotation (objectivity);
//  - triaxial compression at high confinement reaches the Mohr-Coulomb compression strength of
//    the same friction angle and cohesion c = mu (3 - sin phi) / (sqrt(2/3) 6 cos phi) ((3.107));
//  - hydrostatic tension stops on the cap at I1 = sqrt(3) R_t.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "materials/friction_angles.h"
#include "materials/material_driver.h"
#include "materials/smooth_cap_drucker_prager.h"

namespace surge {
namespace {

// Seed column-impact material (Table 7.10): K = 8.33 MPa, G = 3.85 MPa, mu = 10 Pa,
// associativity 0.05; the friction angle and mu vary per test.
SmoothCapDruckerPragerParams Debris(Real phi_deg, Real mu, Real associativity = 0.05) {
  return SmoothCapDruckerPragerParams{8.33e6, 3.85e6, DruckerPragerSlope(Radians(phi_deg)), mu,
                                      associativity};
}
Mat3 Tau(const MaterialPoint& pt) { return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix(); }

TEST(SmoothCapDruckerPragerTest, ReturnsLandOnTheSurfaceInEveryRegion) {
  for (const Real phi : {5.0, 20.0, 40.0}) {
    const SmoothCapDruckerPragerParams p = Debris(phi, 5e3, 0.05);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<Real> u(-1.0, 1.0);
    std::array<int, 4> count{};
    Real worst = 0;
    for (int i = 0; i < 20000; ++i) {
      // Trial stresses around the apex region and far out in compression.
      const Real scale = (i % 2 ? 2e4 : 2e5);
      const Vec3 trial = scale * Vec3(u(rng), u(rng), u(rng)) - (i % 3 == 0 ? 0.0 : scale) * Vec3::Ones();
      Vec3 tau;
      const int region = SmoothCapReturn(p, trial, tau);
      ++count[region];
      const Real f = SmoothCapYield(p, tau);
      if (region == 0) {
        EXPECT_LE(SmoothCapYield(p, trial), 0);
        continue;
      }
      worst = std::max(worst, std::abs(f) / std::max(tau.norm(), p.yield_stress));
      ASSERT_LE(std::abs(f), 1e-8 * std::max(tau.norm(), p.yield_stress)) << "region " << region;
    }
    std::printf("smooth cap phi = %g: elastic %d, cone %d, cap %d, tangent ring %d; max |F|/scale "
                "= %.2e\n", phi, count[0], count[1], count[2], count[3], worst);
    EXPECT_GT(count[1], 100);
    EXPECT_GT(count[2], 100);
    EXPECT_GT(count[3], 10);
  }
}

TEST(SmoothCapDruckerPragerTest, ConeAndCapMeetAtTheTangentRing) {
  const SmoothCapDruckerPragerParams p = Debris(30, 1e3);
  const Real d = 1 + 3 * p.friction_slope * p.friction_slope;
  const Real It = 3 * p.friction_slope * p.yield_stress / d, st = p.yield_stress / d;
  const Vec3 n = Vec3(1, -1, 0).normalized();
  const Vec3 ring = st * n + Vec3::Constant(It / 3);
  const Real cone = st + p.friction_slope * It - p.yield_stress;
  const Real cap = std::sqrt(st * st + It * It / 3) - p.yield_stress / std::sqrt(d);
  EXPECT_NEAR(cone, 0, 1e-12 * p.yield_stress);
  EXPECT_NEAR(cap, 0, 1e-12 * p.yield_stress);
  EXPECT_NEAR(SmoothCapYield(p, ring), 0, 1e-12 * p.yield_stress);
}

TEST(SmoothCapDruckerPragerTest, PlasticVolumeChangeFollowsTheFlowRule) {
  for (const Real assoc : {0.0, 0.05, 1.0}) {
    const SmoothCapDruckerPragerParams p = Debris(30, 10.0, assoc);
    MaterialPoint pt = MakeMaterialPoint(Material{"debris", 1950.55, p}, -20e3 * Mat3::Identity());
    int cone = 0;
    for (int step = 0; step < 300; ++step) {
      const Real volume = pt.particles.history[0][kScdpPlasticVolume];
      const Real strain = pt.particles.history[0][kScdpPlasticStrain];
      Mat3 L = Mat3::Zero();
      L(0, 1) = L(1, 0) = 0.5;  // simple shear rate 1 /s (no spin)
      StepMaterialPoint(pt, L, 1e-4);
      if (pt.particles.history[0][kScdpRegion] != 1) continue;
      ++cone;
      // Cone flow g = n + varrho_G 1 (3.110): ||dev dgamma g|| = dgamma, tr = 3 varrho_G dgamma.
      const Real dgamma = pt.particles.history[0][kScdpPlasticStrain] - strain;
      const Real dv = pt.particles.history[0][kScdpPlasticVolume] - volume;
      EXPECT_NEAR(dv, 3 * assoc * p.friction_slope * dgamma, 1e-9 * dgamma + 1e-15) << step;
    }
    EXPECT_GT(cone, 200) << "associativity " << assoc;
  }
  // Hydrostatic stretch: returns to the cap, associated flow, dilation.
  const SmoothCapDruckerPragerParams p = Debris(30, 1e3);
  MaterialPoint pt = MakeMaterialPoint(Material{"debris", 1950.55, p});
  StepMaterialPoint(pt, 1e-2 * Mat3::Identity(), 1e-1);  // 0.1 % stretch per axis
  EXPECT_EQ(pt.particles.history[0][kScdpRegion], 2);
  EXPECT_GT(pt.particles.history[0][kScdpPlasticVolume], 0);
  const Real radius = p.yield_stress / std::sqrt(1 + 3 * p.friction_slope * p.friction_slope);
  EXPECT_NEAR(Tau(pt).trace(), std::sqrt(3.0) * radius, 1e-9 * radius) << "I1 = sqrt(3) R_t";
  EXPECT_LE(Dev(Tau(pt)).norm(), 1e-9 * radius);
}

TEST(SmoothCapDruckerPragerTest, RigidRotationIsObjective) {
  const SmoothCapDruckerPragerParams p = Debris(20, 500);
  MaterialPoint pt = MakeMaterialPoint(Material{"debris", 1950.55, p}, -10e3 * Mat3::Identity());
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<Real> u(-1.0, 1.0);
  for (int step = 0; step < 100; ++step) {
    Mat3 L;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) L(i, j) = u(rng);
    StepMaterialPoint(pt, L, 1e-4);
  }
  ASSERT_GT(pt.particles.history[0][kScdpPlasticStrain], 0);
  for (int r = 0; r < 10; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const Mat3 R = Eigen::AngleAxis<Real>(3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized())
                       .toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / 1e-4, 1e-4);
    EXPECT_LE((pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm(), 1e-10 * sigma0.norm());
  }
}

TEST(SmoothCapDruckerPragerTest, TriaxialCompressionReachesTheMohrCoulombStrength) {
  const Real phi = 30, mu = 5e3;
  const SmoothCapDruckerPragerParams p = Debris(phi, mu, 0.0);
  // sigma_Y^Eff = -mu in (3.107): c = mu (3 - sin phi) / (sqrt(2/3) 6 cos phi).
  const Real s = std::sin(Radians(phi)), c = mu * (3 - s) / (std::sqrt(2.0 / 3.0) * 6 * std::cos(Radians(phi)));
  MaterialPoint pt = MakeMaterialPoint(Material{"debris", 1950.55, p}, -100e3 * Mat3::Identity());
  MixedControl m;
  m.stress_controlled = {false, true, true, true, true, true};
  m.target = -100e3 * Mat3::Identity();
  m.target(0, 0) = 0;
  for (int step = 0; step < 300; ++step) {
    m.L(0, 0) = -1.0;
    ASSERT_GE(MixedControlStep(pt, m, 1e-4, 1e-6), 0) << "step " << step;
  }
  const Mat3 tau = Tau(pt);
  const Real q = tau(1, 1) - tau(0, 0), pc = -tau.trace() / 3;
  const Real qf = 6 * s / (3 - s) * (pc + c / std::tan(Radians(phi)));
  std::printf("smooth cap triaxial compression: q = %.6g Pa, MC q_f = %.6g Pa\n", q, qf);
  EXPECT_NEAR(q, qf, 1e-6 * qf);
}

}  // namespace
}  // namespace surge

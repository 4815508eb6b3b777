// Mohr-Coulomb and Tresca verification (issue 3; materials/mohr_coulomb.h): the principal return
// and the one-point driver (materials/material_driver.h, the engine's own UpdateStress).
//  - Random trial stresses and random strain paths reach all four return regions (main plane,
//    left edge, right edge, apex); every return ends on the surface (max of the six planes = 0,
//    1e-8 relative), keeps the trial's principal order, and elastic steps stay inside.
//  - f is invariant under permutations of the principal stresses; a permuted strain path gives
//    the permuted stress; rigid rotations leave the invariants unchanged (objectivity).
//  - Dilatancy: d_eps_v^p / (d_eps_1^p - d_eps_3^p) = sin(psi) on the main plane; zero plastic
//    volume change for psi = 0, dilation for psi > 0.
//  - Closed forms (Kirchhoff stress tau = J sigma, compression-positive p', q): triaxial
//    compression q_f = 6 sin(phi) / (3 - sin(phi)) (p' + c cot(phi)), triaxial extension
//    q_f = 6 sin(phi) / (3 + sin(phi)) (p' + c cot(phi)) (mixed control), apex p = c cot(phi) with
//    zero deviator, Tresca pure shear tau_max = s_u; simple shear tends to tau = s_u (Tresca) and
//    to tau = c cos(phi) + sigma_n sin(phi) (psi = 0, constant sigma_n).
//  - Engine: a 1 m vertical cut in Tresca clay stands for s_u = 20 kPa (gamma H / s_u = 0.98 < 2,
//    the lower bound) and collapses for s_u = 2 kPa (gamma H / s_u = 9.8 > 3.83, the upper bound).
//  - Tension cut-off (MohrCoulombCutoffTest): random trials and paths end inside all nine planes,
//    every branch reached; hydrostatic and uniaxial extension stop at t; a block hanging from a
//    ceiling falls only with a cut-off; with t = 0 the cut fails at gamma H / s_u = 3.2 (stands
//    without) and stands at 2.4 (Terzaghi's cracked critical height 2.67).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "../support/run_scene.h"
#include "materials/hencky.h"
#include "materials/material_driver.h"
#include "materials/mohr_coulomb.h"
#include "scene/scene.h"
#include "support/random_paths.h"

namespace surge {
namespace {

constexpr Real kDeg = std::numbers::pi / 180.0;

// Stiff sand with some cohesion: E = 50 MPa, nu = 0.25 (K = 33.3 MPa, G = 20 MPa).
MohrCoulombParams Sand(Real phi_deg, Real psi_deg, Real c) {
  return MohrCoulombParams{50e6 / (3 * (1 - 2 * 0.25)), 50e6 / (2 * 1.25), phi_deg * kDeg,
                           psi_deg * kDeg, c};
}
TrescaParams Clay(Real su) { return TrescaParams{100e6, 2e6, su}; }

Material MaterialOf(const MohrCoulombParams& p) { return Material{"sand", 2000.0, p}; }
Material MaterialOf(const TrescaParams& p) { return Material{"clay", 1800.0, p}; }

Mat3 Tau(const MaterialPoint& pt) {
  return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix();
}
History Hist(const MaterialPoint& pt) { return pt.particles.history.Get(0); }
McRegion RegionOf(const MaterialPoint& pt) {
  return static_cast<McRegion>(static_cast<int>(Hist(pt)[kMcReturnRegion]));
}

// Principal values, largest first.
Vec3 Principal(const Mat3& tau) {
  const Vec3 ascending = Eigen::SelfAdjointEigenSolver<Mat3>(tau, Eigen::EigenvaluesOnly).eigenvalues();
  return Vec3(ascending[2], ascending[1], ascending[0]);
}

// The size of the terms of f: |tau_1| + |tau_3| + 2 c cos(phi) [Pa].
Real YieldScale(const McSurface& s, const Vec3& tau) {
  return std::abs(tau.maxCoeff()) + std::abs(tau.minCoeff()) + 2 * s.cohesion * s.cos_phi;
}

using testing::RandomL;

// A random strain path: segments of 25 steps, each with a fixed random deviatoric direction (unit
// norm) and a volumetric bias cycling through `bias`, plus 20 % noise; L = rate x that [1/s].
class RandomPath {
 public:
  RandomPath(uint64_t seed, Real rate, std::array<Real, 3> bias) : rng_(seed), rate_(rate), bias_(bias) {}
  // `scale` multiplies the rate (e.g. the current strength over the initial one).
  Mat3 Next(Real scale = 1) {
    if (step_ % 25 == 0) {
      direction_ = Dev(Sym(RandomL(rng_, 1))).normalized();
      volumetric_ = bias_[(step_ / 25) % 3];
    }
    ++step_;
    return scale * rate_ * (direction_ + volumetric_ * Mat3::Identity() + 0.2 * RandomL(rng_, 1));
  }

 private:
  std::mt19937_64 rng_;
  Real rate_;
  std::array<Real, 3> bias_;
  int step_ = 0;
  Mat3 direction_ = Mat3::Zero();
  Real volumetric_ = 0;
};

// Compression-positive Cambridge invariants p' = -tr(tau)/3 and q = tau_1 - tau_3 of an axially
// symmetric state (two equal principal values).
struct Pq {
  Real p, q;
};
Pq CambridgePq(const Mat3& tau) {
  const Vec3 t = Principal(tau);
  return Pq{-t.sum() / 3, t[0] - t[2]};
}

// --- principal return ------------------------------------------------------------------------

// Random sorted trial stresses around the surface of phi = 30, psi = 10 deg, c = 20 kPa: every
// return lands on the surface, in order, with multipliers >= 0; all four regions are hit.
TEST(MohrCoulombReturnTest, RandomTrialsReachEveryRegionAndEndOnTheSurface) {
  const MohrCoulombParams p = Sand(30, 10, 20e3);
  const McSurface s = SurfaceOf(p);
  const Real K = p.bulk_modulus, G = p.shear_modulus;
  const Real apex = s.cohesion * s.cos_phi / s.sin_phi;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<Real> u(-400e3, 100e3);
  std::array<int, 5> count{};
  Real worst = 0, worst_ratio = 0;
  for (int n = 0; n < 20000; ++n) {
    Vec3 trial(u(rng), u(rng), u(rng));
    std::sort(trial.data(), trial.data() + 3, std::greater<Real>());
    const McReturn r = MohrCoulombReturn(s, K, G, trial);
    ++count[static_cast<int>(r.region)];
    const Real scale = YieldScale(s, trial);
    if (r.region == McRegion::kElastic) {
      ASSERT_LE(MohrCoulombYield(s, trial), 0);
      continue;
    }
    const Real f = MohrCoulombYield(s, r.tau);
    worst = std::max(worst, std::abs(f) / scale);
    ASSERT_LE(std::abs(f), 1e-8 * scale) << "trial " << trial.transpose();
    ASSERT_GE(r.tau[0] - r.tau[1], -1e-10 * scale);  // order kept
    ASSERT_GE(r.tau[1] - r.tau[2], -1e-10 * scale);
    ASSERT_GE(r.dgamma[0], 0);
    ASSERT_GE(r.dgamma[1], 0);
    const Vec3 deps_p = HenckyStrain(K, G, trial) - HenckyStrain(K, G, r.tau);
    switch (r.region) {
      case McRegion::kMainPlane: {
        // g_13: d_eps^p = dgamma (1 + sin psi, 0, -(1 - sin psi)): tr / (e1 - e3) = sin psi.
        const Real ratio = deps_p.sum() / (deps_p[0] - deps_p[2]);
        worst_ratio = std::max(worst_ratio, std::abs(ratio - s.sin_psi));
        ASSERT_NEAR(ratio, s.sin_psi, 1e-8);
        ASSERT_NEAR(deps_p[1], 0, 1e-8 * std::abs(deps_p[0]));
        break;
      }
      case McRegion::kLeftEdge:
        ASSERT_NEAR(r.tau[0], r.tau[1], 1e-10 * scale);
        ASSERT_NEAR(deps_p.sum(), 2 * s.sin_psi * (r.dgamma[0] + r.dgamma[1]), 1e-8 * deps_p.norm());
        break;
      case McRegion::kRightEdge:
        ASSERT_NEAR(r.tau[1], r.tau[2], 1e-10 * scale);
        ASSERT_NEAR(deps_p.sum(), 2 * s.sin_psi * (r.dgamma[0] + r.dgamma[1]), 1e-8 * deps_p.norm());
        break;
      case McRegion::kApex:
        for (int i = 0; i < 3; ++i) ASSERT_NEAR(r.tau[i], apex, 1e-12 * apex);
        ASSERT_GT(trial.sum() / 3, apex);  // only a trial beyond the apex in p goes there
        break;
      default:
        break;
    }
  }
  std::printf("MC principal return, 20000 random trials: elastic %d, main %d, left edge %d, right "
              "edge %d, apex %d; max |f|/scale %.2e; max |tr/(e1-e3) - sin psi| %.2e\n",
              count[0], count[1], count[2], count[3], count[4], worst, worst_ratio);
  for (int i = 0; i < 5; ++i) EXPECT_GT(count[i], 50) << "region " << i;
}

// f is the max of the six planes (7.26): the same for every order of the principal stresses.
TEST(MohrCoulombReturnTest, YieldFunctionIsInvariantUnderPermutations) {
  const McSurface s = SurfaceOf(Sand(35, 5, 10e3));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<Real> u(-300e3, 50e3);
  Real worst = 0;
  for (int n = 0; n < 1000; ++n) {
    std::array<Real, 3> v = {u(rng), u(rng), u(rng)};
    std::sort(v.begin(), v.end());
    const Real f0 = MohrCoulombYield(s, Vec3(v[2], v[1], v[0]));
    // Explicit max over the six ordered pairs i != j of f_ij.
    Real f6 = -1e300;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j) f6 = std::max(f6, (v[i] - v[j]) + (v[i] + v[j]) * s.sin_phi -
                                          2 * s.cohesion * s.cos_phi);
    EXPECT_NEAR(f6, f0, 1e-9 * std::abs(f0));
    do {
      const Real f = MohrCoulombYield(s, Vec3(v[0], v[1], v[2]));
      worst = std::max(worst, std::abs(f - f0));
      ASSERT_EQ(f, f0);
    } while (std::next_permutation(v.begin(), v.end()));
  }
  std::printf("MC f under the 6 permutations of 1000 random states: max difference %.1e Pa\n",
              worst);
}

// --- one-point driver ------------------------------------------------------------------------

struct DriverCase {
  const char* name;
  bool tresca;
  Real phi_deg, psi_deg, c;
};
class MohrCoulombDriverTest : public ::testing::TestWithParam<DriverCase> {
 protected:
  Material Mat() const {
    const DriverCase& d = GetParam();
    return d.tresca ? MaterialOf(Clay(d.c)) : MaterialOf(Sand(d.phi_deg, d.psi_deg, d.c));
  }
  McSurface Surface() const {
    const DriverCase& d = GetParam();
    return d.tresca ? SurfaceOf(Clay(d.c)) : SurfaceOf(Sand(d.phi_deg, d.psi_deg, d.c));
  }
  Real K() const { return GetParam().tresca ? Clay(1).bulk_modulus : Sand(30, 0, 0).bulk_modulus; }
  Real G() const {
    return GetParam().tresca ? Clay(1).shear_modulus : Sand(30, 0, 0).shear_modulus;
  }
};

// Random strain paths (RandomPath: increments of about 0.3 of the current yield strain,
// segments with compressive, neutral and tensile volumetric bias): every plastic step ends on the surface, elastic steps
// stay inside, the return keeps the order of the trial principal values in the trial frame, and
// every region of the model is exercised.
TEST_P(MohrCoulombDriverTest, RandomPathsReachEveryRegionAndEndOnTheSurface) {
  const McSurface s = Surface();
  const bool has_apex = s.sin_phi > 0;
  MaterialPoint pt = MakeMaterialPoint(Mat(), -50e3 * Mat3::Identity());
  // Strain increments of about 0.3 x the current yield strain (c cos(phi) + p' sin(phi)) / G,
  // capped at 3 x the initial one (dilation under a prescribed volume raises p').
  const Real strength0 = s.cohesion * s.cos_phi + 50e3 * s.sin_phi;
  auto strength = [&](const Mat3& tau) {
    return std::min(s.cohesion * s.cos_phi + std::max(-tau.trace() / 3, 0.0) * s.sin_phi,
                    3 * strength0);
  };
  const Real dt = 1e-3, rate = 0.3 / G() / dt;
  RandomPath path(42, rate, {-0.3, 0.3, 0.6});
  std::array<int, 5> count{};
  Real worst = 0, worst_order = 0;
  for (int step = 0; step < 6000; ++step) {
    const Mat3 L = path.Next(strength(Tau(pt)));
    const HenckyTrial t = HenckyTrialState(K(), G(), Mat3::Identity() + dt * L,
                                           pt.particles.elastic_b[0]);
    StepMaterialPoint(pt, L, dt);
    const McRegion region = RegionOf(pt);
    ++count[static_cast<int>(region)];
    const Mat3 tau = Tau(pt);
    const Vec3 tp = Principal(tau);
    const Real scale = YieldScale(s, tp);
    const Real f = MohrCoulombYield(s, tp);
    if (region == McRegion::kElastic) {
      ASSERT_LE(f, 1e-8 * scale) << "elastic step " << step << " outside the surface";
      continue;
    }
    worst = std::max(worst, std::abs(f) / scale);
    ASSERT_LE(std::abs(f), 1e-8 * scale) << "step " << step;
    // Coaxial with the trial, and the principal order of the trial survives the return.
    const Mat3 hat = t.Q.transpose() * tau * t.Q;
    ASSERT_LE((hat - Mat3(hat.diagonal().asDiagonal())).norm(), 1e-10 * scale);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (t.tau[i] > t.tau[j]) {
          worst_order = std::max(worst_order, (hat(j, j) - hat(i, i)) / scale);
          ASSERT_GE(hat(i, i) - hat(j, j), -1e-10 * scale) << "step " << step;
        }
  }
  std::printf("%s random path, 6000 steps: elastic %d, main %d, left edge %d, right edge %d, "
              "apex %d; max |f|/scale %.2e, worst order violation %.1e, eps_p = %.4f, "
              "eps_v^p = %.4f\n", GetParam().name, count[0], count[1], count[2], count[3],
              count[4], worst, worst_order, Hist(pt)[kMcPlasticStrain],
              Hist(pt)[kMcVolumetricPlastic]);
  for (int i = 0; i < 4; ++i) EXPECT_GE(count[i], 10) << "region " << i;
  if (has_apex) {
    EXPECT_GE(count[4], 10) << "apex";
  } else {
    EXPECT_EQ(count[4], 0) << "Tresca has no apex";
  }
}

// Rigid rotations (f = R exactly) of a plastically strained point: sigma -> R sigma R^T, the
// invariants and the history unchanged.
TEST_P(MohrCoulombDriverTest, RigidRotationLeavesInvariantsUnchanged) {
  MaterialPoint pt = MakeMaterialPoint(Mat(), -50e3 * Mat3::Identity());
  const Real dt = 1e-3, rate = 0.5 * Surface().cohesion / G() / dt;
  RandomPath path(7, rate, {-0.3, -0.1, -0.3});
  for (int step = 0; step < 100; ++step) StepMaterialPoint(pt, path.Next(), dt);
  std::mt19937_64 rng(8);
  ASSERT_GT(Hist(pt)[kMcPlasticStrain], 0) << "the point must be plastic";
  std::uniform_real_distribution<Real> angle(-3.0, 3.0);
  Real worst = 0;
  for (int r = 0; r < 20; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const History h0 = Hist(pt);
    const Vec3 axis = Vec3(angle(rng), angle(rng), angle(rng)).normalized();
    const Mat3 R = Eigen::AngleAxis<Real>(angle(rng), axis).toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / dt, dt);
    const Real scale = sigma0.norm();
    const Real err = (pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm() / scale;
    worst = std::max(worst, err);
    EXPECT_LE(err, 1e-10);
    EXPECT_LE((Principal(pt.particles.stress[0].matrix()) - Principal(sigma0)).norm(), 1e-10 * scale);
    EXPECT_EQ(RegionOf(pt), McRegion::kElastic);
    EXPECT_EQ(Hist(pt)[kMcPlasticStrain], h0[kMcPlasticStrain]);
  }
  std::printf("%s: rigid rotations, max |sigma - R sigma0 R^T| / |sigma0| = %.2e\n",
              GetParam().name, worst);
}

// The same random path in axes permuted by P gives P sigma P^T: the return does not depend on
// the order in which the eigen-solver delivers the principal values.
TEST_P(MohrCoulombDriverTest, PermutedPathGivesPermutedStress) {
  Mat3 P;
  P << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  MaterialPoint a = MakeMaterialPoint(Mat(), -50e3 * Mat3::Identity());
  MaterialPoint b = a;
  const Real dt = 1e-3, rate = 0.5 * Surface().cohesion / G() / dt;
  RandomPath path(9, rate, {-0.3, 0, 0.3});
  Real worst = 0;
  for (int step = 0; step < 1000; ++step) {
    const Mat3 L = path.Next();
    StepMaterialPoint(a, L, dt);
    StepMaterialPoint(b, P * L * P.transpose(), dt);
    const Mat3 sa = P * a.particles.stress[0].matrix() * P.transpose();
    const Real err = (b.particles.stress[0].matrix() - sa).norm() / sa.norm();
    worst = std::max(worst, err);
    ASSERT_LE(err, 1e-9) << "step " << step;
  }
  EXPECT_GT(Hist(a)[kMcPlasticStrain], 0);
  EXPECT_NEAR(Hist(b)[kMcPlasticStrain], Hist(a)[kMcPlasticStrain], 1e-9 * Hist(a)[kMcPlasticStrain]);
  std::printf("%s: permuted path, max |sigma_P - P sigma P^T| / |sigma| = %.2e\n", GetParam().name,
              worst);
}

INSTANTIATE_TEST_SUITE_P(
    Models, MohrCoulombDriverTest,
    ::testing::Values(DriverCase{"MC phi30 psi10 c20k", false, 30, 10, 20e3},
                      DriverCase{"MC phi35 psi0 c10k", false, 35, 0, 10e3},
                      DriverCase{"MC phi30 psi30 c5k", false, 30, 30, 5e3},
                      DriverCase{"Tresca su30k", true, 0, 0, 30e3}),
    [](const ::testing::TestParamInfo<DriverCase>& info) {
      std::string n = info.param.name;
      std::replace_if(n.begin(), n.end(), [](char ch) { return !std::isalnum(ch); }, '_');
      return n;
    });

// Plastic volume change has the sign of psi: on a compressive random path (no apex returns)
// eps_v^p stays 0 for psi = 0 and grows (dilation) for psi > 0, faster for larger psi.
TEST(MohrCoulombDilatancyTest, PlasticVolumeChangeFollowsTheDilationAngle) {
  std::array<Real, 3> eps_v{}, eps_q{};
  const Real psi[3] = {0, 10, 30};
  for (int k = 0; k < 3; ++k) {
    const MohrCoulombParams p = Sand(30, psi[k], 20e3);
    MaterialPoint pt = MakeMaterialPoint(MaterialOf(p), -100e3 * Mat3::Identity());
    std::mt19937_64 rng(3);
    const Real dt = 1e-3, rate = 2e-3 / dt;
    for (int step = 0; step < 2000; ++step) {
      StepMaterialPoint(pt, RandomL(rng, rate) - 0.3 * rate * Mat3::Identity(), dt);
      ASSERT_NE(RegionOf(pt), McRegion::kApex) << "the path must stay compressive";
    }
    eps_v[k] = Hist(pt)[kMcVolumetricPlastic];
    eps_q[k] = Hist(pt)[kMcPlasticStrain];
  }
  std::printf("MC phi = 30 deg, compressive random path: eps_v^p = %.3e / %.3e / %.3e for psi = "
              "0 / 10 / 30 deg (eps_p = %.3f / %.3f / %.3f)\n", eps_v[0], eps_v[1], eps_v[2],
              eps_q[0], eps_q[1], eps_q[2]);
  EXPECT_LE(std::abs(eps_v[0]), 1e-12 * eps_q[0]);
  EXPECT_GT(eps_v[1], 0.01 * eps_q[1]);
  EXPECT_GT(eps_v[2], eps_v[1]);
}

// Drained triaxial test by mixed control (spec §2.10): isotropic start at sigma = -p0 1, the
// radial Cauchy stresses held at -p0, the axial stretch prescribed (compression: rate < 0,
// extension: rate > 0). Returns the final point; `last_region` the region of the final step.
MaterialPoint Triaxial(const MohrCoulombParams& p, Real p0, Real axial_rate, int steps,
                       Real& max_q) {
  MaterialPoint pt = MakeMaterialPoint(MaterialOf(p), -p0 * Mat3::Identity());
  MixedControl c;
  c.stress_controlled = {true, true, false, true, true, true};
  c.target = -p0 * Vec3(1, 1, 0).asDiagonal().toDenseMatrix();
  const Real dt = 1e-3;
  c.L(2, 2) = axial_rate;
  max_q = 0;
  for (int n = 0; n < steps; ++n) {
    EXPECT_GE(MixedControlStep(pt, c, dt, 1e-7 * p0), 0) << "step " << n;
    max_q = std::max(max_q, CambridgePq(Tau(pt)).q);
  }
  return pt;
}

TEST(MohrCoulombTriaxialTest, CompressionReachesTheClosedFormStrength) {
  for (const Real psi : {0.0, 10.0}) {
    const MohrCoulombParams p = Sand(30, psi, 20e3);
    const McSurface s = SurfaceOf(p);
    const Real p0 = 100e3, cot = s.cos_phi / s.sin_phi;
    Real max_q = 0;
    MaterialPoint pt = Triaxial(p, p0, -2e-4 / 1e-3, 300, max_q);  // 6 % axial strain
    const Pq pq = CambridgePq(Tau(pt));
    const Real q_f = 6 * s.sin_phi / (3 - s.sin_phi) * (pq.p + s.cohesion * cot);
    // The same with p' = tau_r + q/3 eliminated: q_f = 2 sin(phi) / (1 - sin(phi)) (tau_r + c cot).
    const Real tau_r = -Tau(pt)(0, 0);
    const Real q_f_radial = 2 * s.sin_phi / (1 - s.sin_phi) * (tau_r + s.cohesion * cot);
    std::printf("MC triaxial compression phi = 30, psi = %.0f, c = 20 kPa, p0 = 100 kPa: q = %.6e "
                "Pa, q_f = 6 sin/(3 - sin)(p' + c cot) = %.6e Pa (rel. %.1e), from tau_r: %.6e Pa, "
                "eps_v^p = %.3e\n", psi, pq.q, q_f, std::abs(pq.q - q_f) / q_f, q_f_radial,
                Hist(pt)[kMcVolumetricPlastic]);
    EXPECT_EQ(RegionOf(pt), McRegion::kLeftEdge);  // tau_1 = tau_2: compression meridian
    EXPECT_NEAR(pq.q, q_f, 1e-6 * q_f);
    EXPECT_NEAR(pq.q, q_f_radial, 1e-6 * q_f);
    EXPECT_LE(max_q, q_f * (1 + 1e-6));  // perfect plasticity: q never overshoots
    if (psi > 0) EXPECT_GT(Hist(pt)[kMcVolumetricPlastic], 0);
    else EXPECT_NEAR(Hist(pt)[kMcVolumetricPlastic], 0, 1e-12);
  }
}

TEST(MohrCoulombTriaxialTest, ExtensionReachesTheClosedFormStrength) {
  const MohrCoulombParams p = Sand(30, 10, 20e3);
  const McSurface s = SurfaceOf(p);
  const Real p0 = 100e3, cot = s.cos_phi / s.sin_phi;
  Real max_q = 0;
  MaterialPoint pt = Triaxial(p, p0, 2e-4 / 1e-3, 300, max_q);
  const Pq pq = CambridgePq(Tau(pt));
  const Real q_f = 6 * s.sin_phi / (3 + s.sin_phi) * (pq.p + s.cohesion * cot);
  std::printf("MC triaxial extension phi = 30, psi = 10, c = 20 kPa, p0 = 100 kPa: q = %.6e Pa, "
              "q_f = 6 sin/(3 + sin)(p' + c cot) = %.6e Pa (rel. %.1e), p' = %.4e Pa\n", pq.q, q_f,
              std::abs(pq.q - q_f) / q_f, pq.p);
  EXPECT_EQ(RegionOf(pt), McRegion::kRightEdge);  // tau_2 = tau_3: extension meridian
  EXPECT_GT(Tau(pt)(2, 2), Tau(pt)(0, 0));        // the axis is the largest principal stress
  EXPECT_NEAR(pq.q, q_f, 1e-6 * q_f);
  EXPECT_LE(max_q, q_f * (1 + 1e-6));
}

// Hydrostatic extension past the apex: tau = c cot(phi) 1, zero deviator, plastic dilation.
TEST(MohrCoulombApexTest, HydrostaticTensionStopsAtTheApex) {
  const MohrCoulombParams p = Sand(30, 10, 20e3);
  const McSurface s = SurfaceOf(p);
  const Real apex = s.cohesion * s.cos_phi / s.sin_phi;
  MaterialPoint pt = MakeMaterialPoint(MaterialOf(p), -50e3 * Mat3::Identity());
  const Real dt = 1e-3, rate = 0.5e-3 / dt;
  int apex_steps = 0;
  for (int n = 0; n < 20; ++n) {
    StepMaterialPoint(pt, rate * Mat3::Identity(), dt);
    if (RegionOf(pt) != McRegion::kApex) continue;
    ++apex_steps;
    const Mat3 tau = Tau(pt);
    EXPECT_NEAR(tau.trace() / 3, apex, 1e-12 * apex);
    EXPECT_LE(Dev(tau).norm(), 1e-12 * apex);
  }
  std::printf("MC apex: %d of 20 steps at the apex, p = %.6e Pa (c cot phi = %.6e Pa), |dev| = "
              "%.1e, eps_v^p = %.4e\n", apex_steps, Tau(pt).trace() / 3, apex,
              Dev(Tau(pt)).norm(), Hist(pt)[kMcVolumetricPlastic]);
  EXPECT_GE(apex_steps, 15);
  // All volumetric strain beyond the apex is plastic: ln J - ln J^e, ln J^e = (apex + 50 kPa)/K.
  const Real lnJ = std::log(pt.particles.F[0].determinant());
  EXPECT_NEAR(Hist(pt)[kMcVolumetricPlastic], lnJ - apex / p.bulk_modulus + (-50e3) / p.bulk_modulus,
              1e-12);
}

// Tresca, isochoric pure shear f = diag(l, 1/l, 1): tau_max = (tau_xx - tau_yy)/2 -> s_u exactly.
TEST(TrescaTest, PureShearLimitIsTheUndrainedStrength) {
  const TrescaParams p = Clay(30e3);
  MaterialPoint pt = MakeMaterialPoint(MaterialOf(p));
  const Real dt = 1e-3, l = std::exp(2e-3);
  Mat3 L = Mat3::Zero();
  L(0, 0) = (l - 1) / dt;
  L(1, 1) = (1 / l - 1) / dt;
  int plastic = 0;
  Real worst = 0;
  for (int n = 0; n < 100; ++n) {
    StepMaterialPoint(pt, L, dt);
    const Mat3 tau = Tau(pt);
    const Real tau_max = 0.5 * (tau(0, 0) - tau(1, 1));
    if (RegionOf(pt) == McRegion::kElastic) {
      // Elastic: tau_max = 2 G eps_xx with eps_xx = (n + 1) ln l.
      EXPECT_NEAR(tau_max, 2 * p.shear_modulus * (n + 1) * std::log(l), 1e-9 * p.undrained_strength);
      continue;
    }
    ++plastic;
    worst = std::max(worst, std::abs(tau_max - p.undrained_strength) / p.undrained_strength);
    EXPECT_NEAR(tau_max, p.undrained_strength, 1e-10 * p.undrained_strength);
    EXPECT_NEAR(tau.trace(), 0, 1e-9 * p.undrained_strength);  // undrained: no mean stress
  }
  std::printf("Tresca pure shear: %d plastic steps of 100, tau_max = %.8e Pa (s_u = %.8e), max "
              "rel. error %.1e\n", plastic, 0.5 * (Tau(pt)(0, 0) - Tau(pt)(1, 1)),
              p.undrained_strength, worst);
  EXPECT_GT(plastic, 50);
}

// Simple shear (f = I + dt L, L_xy = gamma_dot): the horizontal shear stress approaches the
// strength of the horizontal plane. Tresca: tau_xy -> s_u. Mohr-Coulomb with psi = 0 at constant
// sigma_yy (mixed control): tau_xy -> c cos(phi) + sigma_n sin(phi) (the plastic strain rate is
// simple shear only when the principal axes are at 45 deg, where tau_xy is the Mohr radius). The
// limits are asymptotic (elastic strains and the finite rotation of the axes), so the check is 1 %.
TEST(SimpleShearTest, HorizontalShearStressApproachesThePlaneStrength) {
  const Real dt = 1e-3;
  {
    const TrescaParams p = Clay(30e3);
    MaterialPoint pt = MakeMaterialPoint(MaterialOf(p));
    Mat3 L = Mat3::Zero();
    L(0, 1) = 2e-3 / dt;
    for (int n = 0; n < 150; ++n) StepMaterialPoint(pt, L, dt);  // gamma = 0.3
    const Mat3 tau = Tau(pt);
    std::printf("Tresca simple shear to gamma = 0.3: tau_xy = %.5e Pa (s_u = %.5e, ratio %.5f), "
                "tau_max = %.8e\n", tau(0, 1), p.undrained_strength, tau(0, 1) / p.undrained_strength,
                0.5 * (Principal(tau)[0] - Principal(tau)[2]));
    EXPECT_NEAR(tau(0, 1), p.undrained_strength, 0.01 * p.undrained_strength);
    EXPECT_NEAR(0.5 * (Principal(tau)[0] - Principal(tau)[2]), p.undrained_strength,
                1e-10 * p.undrained_strength);
  }
  {
    const MohrCoulombParams p = Sand(30, 0, 10e3);
    const McSurface s = SurfaceOf(p);
    const Real sigma_n = 100e3;
    MaterialPoint pt = MakeMaterialPoint(MaterialOf(p), -sigma_n * Mat3::Identity());
    MixedControl c;
    c.stress_controlled = {false, true, false, false, false, false};
    c.target(1, 1) = -sigma_n;
    c.L(0, 1) = 2e-3 / dt;
    for (int n = 0; n < 150; ++n) ASSERT_GE(MixedControlStep(pt, c, dt, 1e-7 * sigma_n), 0);
    const Mat3 tau = Tau(pt);
    const Real tau_n = -tau(1, 1);
    const Real limit = s.cohesion * s.cos_phi + tau_n * s.sin_phi;
    std::printf("MC phi = 30, psi = 0, c = 10 kPa simple shear at sigma_n = 100 kPa, gamma = 0.3: "
                "tau_xy = %.5e Pa, c cos(phi) + sigma_n sin(phi) = %.5e Pa (ratio %.5f); tau_xx = "
                "%.4e, tau_zz = %.4e\n", tau(0, 1), limit, tau(0, 1) / limit, tau(0, 0), tau(2, 2));
    EXPECT_NEAR(tau(0, 1), limit, 0.01 * limit);
  }
}

// --- engine run -------------------------------------------------------------------------------

// scenes/vertical_cut_2d.yaml: a 1 m high, 1.5 m wide block of Tresca clay (rho = 2000 kg/m^3)
// against a smooth wall at x = 0 on a rough floor: a vertical cut at x = 1.5 m, s_u from the
// stability number N = gamma H / s_u. Limit analysis (Chen 1975): the cut stands if N < 2 (lower
// bound) and collapses if N > 3.83 (upper bound). The scene has tension_cutoff: 0; `cutoff`
// false lifts it out of reach (1e12 Pa: the cut-off never acts, bitwise as without the key).
struct CutRun {
  Real max_dx;      // largest horizontal displacement of a particle [m]
  Real mean_speed;  // mass-weighted mean speed at the end [m/s]
  Real max_eps_p;   // largest equivalent plastic strain
  Real seconds;     // wall time
};
CutRun RunCut(Real N, bool cutoff) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> overrides = {"parameters.N=" + std::to_string(N)};
  if (!cutoff) overrides.push_back("materials.clay.tension_cutoff=1e12");
  LoadedScene scene = LoadScene(testing::ScenePath("vertical_cut_2d.yaml"), overrides);
  const Particles& P = scene.state.particles;
  std::vector<Real> x0(P.size());  // by particle id (the engine may reorder particles)
  for (size_t i = 0; i < P.size(); ++i) x0[P.id[i]] = P.x[i].x();
  testing::RunUntil(scene, 1.2, [](const State&, const StepReport&) {});
  CutRun r{0, 0, 0, 0};
  Real m = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    r.max_dx = std::max(r.max_dx, P.x[i].x() - x0[P.id[i]]);
    r.mean_speed += P.mass[i] * P.v[i].norm();
    r.max_eps_p = std::max(r.max_eps_p, P.history[i][kMcPlasticStrain]);
    m += P.mass[i];
  }
  r.mean_speed /= m;
  r.seconds = std::chrono::duration<Real>(std::chrono::steady_clock::now() - start).count();
  return r;
}

// --- tension cut-off (Rankine planes tau_i <= t, associated) -----------------------------------

// Random sorted trials (a quarter of them near the hydrostatic axis) for Mohr-Coulomb (phi = 30,
// psi = 10 deg, c = 20 kPa: apex 34.6 kPa) and Tresca (s_u = 30 kPa) with t = 10 kPa. Where the plain return keeps tau_1 <= t the cut-off
// return is bitwise the plain one; elsewhere it ends on tau_1 = t inside all nine planes (1e-8
// relative), in order, with multipliers >= 0, and every branch is reached: tau_1 = t alone (its
// plastic strain along e_1 only), tau_1 = tau_2 = t, tau = t 1, and a corner with a Mohr-Coulomb
// plane.
TEST(MohrCoulombCutoffTest, RandomTrialsEndInsideAllNinePlanes) {
  for (const bool tresca : {false, true}) {
    const MohrCoulombParams sand = Sand(30, 10, 20e3);
    const TrescaParams clay = Clay(30e3);
    McSurface s = tresca ? SurfaceOf(clay) : SurfaceOf(sand);
    const Real K = tresca ? clay.bulk_modulus : sand.bulk_modulus;
    const Real G = tresca ? clay.shear_modulus : sand.shear_modulus;
    const McSurface plain = s;
    s.tension = 10e3;
    const Real t = s.tension;
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<Real> u(-300e3, 300e3), near(-20e3, 20e3);
    int same = 0, single = 0, pair = 0, triple = 0, corner = 0;
    for (int n = 0; n < 20000; ++n) {
      // Every fourth trial near the hydrostatic axis (Tresca reaches tau = t 1 only from there).
      Vec3 trial(u(rng), u(rng), u(rng));
      if (n % 4 == 0) trial = Vec3::Constant(trial[0]) + Vec3(near(rng), near(rng), near(rng));
      std::sort(trial.data(), trial.data() + 3, std::greater<Real>());
      const McReturn r0 = MohrCoulombReturn(plain, K, G, trial);
      const McReturn r = MohrCoulombReturn(s, K, G, trial);
      if (r0.tau[0] <= t) {
        ASSERT_EQ(r.region, r0.region);
        for (int i = 0; i < 3; ++i) ASSERT_EQ(r.tau[i], r0.tau[i]);
        ++same;
        continue;
      }
      const Real scale = YieldScale(s, trial) + t;
      ASSERT_EQ(r.region, McRegion::kTension) << "trial " << trial.transpose();
      ASSERT_NEAR(r.tau[0], t, 1e-8 * scale) << "trial " << trial.transpose();
      ASSERT_LE(MohrCoulombYield(s, r.tau), 1e-8 * scale) << "trial " << trial.transpose();
      ASSERT_GE(r.tau[0] - r.tau[1], -1e-8 * scale);
      ASSERT_GE(r.tau[1] - r.tau[2], -1e-8 * scale);
      ASSERT_GE(r.dgamma[0], 0);
      ASSERT_GE(r.dgamma[1], 0);
      const bool on2 = std::abs(r.tau[1] - t) <= 1e-8 * scale;
      const bool on3 = std::abs(r.tau[2] - t) <= 1e-8 * scale;
      const bool on_mc = std::abs(MohrCoulombYield(s, r.tau)) <= 1e-8 * scale;
      if (on3) {
        ++triple;
      } else if (on2) {
        ++pair;
      } else if (on_mc) {
        ++corner;
      } else {
        ++single;
        // Associated Rankine flow: the plastic strain of tau_1 = t alone is along e_1.
        const Vec3 deps_p = HenckyStrain(K, G, trial) - HenckyStrain(K, G, r.tau);
        ASSERT_GT(deps_p[0], 0);
        ASSERT_NEAR(deps_p[1], 0, 1e-8 * deps_p[0]);
        ASSERT_NEAR(deps_p[2], 0, 1e-8 * deps_p[0]);
      }
    }
    std::printf("%s with a 10 kPa cut-off, 20000 random trials: plain return kept %d, tau_1 = t "
                "%d, tau_1 = tau_2 = t %d, tau = t 1 %d, corner with a shear plane %d\n",
                tresca ? "Tresca" : "Mohr-Coulomb", same, single, pair, triple, corner);
    EXPECT_GT(same, 1000);
    EXPECT_GT(single, 100);
    EXPECT_GT(pair, 20);
    EXPECT_GT(triple, 20);
    EXPECT_GT(corner, 100);
  }
}

// The engine's one-point update with a cut-off (t = 5 kPa) on random paths biased to tension:
// every step ends inside all nine planes, coaxial with the trial and in its order, the cut-off is
// reached often, and then rigid rotations rotate the stress (objectivity).
TEST(MohrCoulombCutoffTest, RandomPathsStayInsideAndRotationsRotateTheStress) {
  for (const bool tresca : {false, true}) {
    MohrCoulombParams sand = Sand(30, 10, 20e3);
    TrescaParams clay = Clay(30e3);
    sand.tension_cutoff = clay.tension_cutoff = 5e3;
    const Material mat = tresca ? MaterialOf(clay) : MaterialOf(sand);
    const McSurface s = tresca ? SurfaceOf(clay) : SurfaceOf(sand);
    const Real K = tresca ? clay.bulk_modulus : sand.bulk_modulus;
    const Real G = tresca ? clay.shear_modulus : sand.shear_modulus;
    MaterialPoint pt = MakeMaterialPoint(mat, -20e3 * Mat3::Identity());
    const Real dt = 1e-3, rate = 0.3 * 20e3 / G / dt;
    RandomPath path(23, rate, {0.3, 0.6, -0.2});
    int cut = 0;
    for (int step = 0; step < 3000; ++step) {
      const Mat3 L = path.Next();
      const HenckyTrial t = HenckyTrialState(K, G, Mat3::Identity() + dt * L,
                                             pt.particles.elastic_b[0]);
      StepMaterialPoint(pt, L, dt);
      const Mat3 tau = Tau(pt);
      const Vec3 tp = Principal(tau);
      const Real scale = YieldScale(s, tp) + s.tension;
      ASSERT_LE(MohrCoulombYield(s, tp), 1e-8 * scale) << "step " << step;
      ASSERT_LE(tp[0] - s.tension, 1e-8 * scale) << "step " << step;
      if (RegionOf(pt) == McRegion::kElastic) continue;
      cut += RegionOf(pt) == McRegion::kTension;
      const Mat3 hat = t.Q.transpose() * tau * t.Q;
      ASSERT_LE((hat - Mat3(hat.diagonal().asDiagonal())).norm(), 1e-10 * scale);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          if (t.tau[i] > t.tau[j]) {
            ASSERT_GE(hat(i, i) - hat(j, j), -1e-8 * scale);
          }
        }
    }
    std::printf("%s, t = 5 kPa, 3000-step random path: %d steps on the cut-off\n",
                tresca ? "Tresca" : "Mohr-Coulomb", cut);
    EXPECT_GE(cut, 50);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<Real> angle(-3.0, 3.0);
    for (int r = 0; r < 10; ++r) {
      const Mat3 sigma0 = pt.particles.stress[0].matrix();
      const Mat3 R = Eigen::AngleAxis<Real>(
          angle(rng), Vec3(angle(rng), angle(rng), angle(rng)).normalized()).toRotationMatrix();
      StepMaterialPoint(pt, (R - Mat3::Identity()) / dt, dt);
      EXPECT_LE((pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm(),
                1e-10 * (sigma0.norm() + s.tension));
    }
  }
}

// Hydrostatic extension with t = 10 kPa below the apex (34.6 kPa): tau -> t 1, zero deviator, and
// all volume change beyond it plastic.
TEST(MohrCoulombCutoffTest, HydrostaticTensionStopsAtTheCutoff) {
  MohrCoulombParams p = Sand(30, 10, 20e3);
  p.tension_cutoff = 10e3;
  MaterialPoint pt = MakeMaterialPoint(MaterialOf(p), -50e3 * Mat3::Identity());
  const Real dt = 1e-3, rate = 0.5e-3 / dt;
  int cut_steps = 0;
  for (int n = 0; n < 20; ++n) {
    StepMaterialPoint(pt, rate * Mat3::Identity(), dt);
    if (RegionOf(pt) != McRegion::kTension) continue;
    ++cut_steps;
    EXPECT_NEAR(Tau(pt).trace() / 3, 10e3, 1e-9 * 10e3);
    EXPECT_LE(Dev(Tau(pt)).norm(), 1e-9 * 10e3);
  }
  EXPECT_GE(cut_steps, 15);
  const Real lnJ = std::log(pt.particles.F[0].determinant());
  EXPECT_NEAR(Hist(pt)[kMcVolumetricPlastic], lnJ - (10e3 + 50e3) / p.bulk_modulus, 1e-12);
}

// Uniaxial strain extension f = diag(1 + e, 1, 1) from zero stress: the axial stress rises
// elastically (lateral nu/(1 - nu) of it) to t = 10 kPa and stays there, the lateral stresses
// frozen (the cut-off's plastic strain is axial only); without the cut-off it passes t and
// yields on the shear plane (tau_xx = 26 kPa).
TEST(MohrCoulombCutoffTest, UniaxialExtensionHoldsTheAxialStressAtTheCutoff) {
  MohrCoulombParams p = Sand(30, 10, 20e3);
  const MohrCoulombParams plain = p;
  p.tension_cutoff = 10e3;
  MaterialPoint pt = MakeMaterialPoint(MaterialOf(p)), ref = MakeMaterialPoint(MaterialOf(plain));
  const Real dt = 1e-3;
  Mat3 L = Mat3::Zero();
  L(0, 0) = 2e-5 / dt;  // 2e-5 strain per step: t / E' = 1.7e-4, about 8 steps to the cut-off
  Real lateral_at_cut = 0;
  int cut_steps = 0;
  for (int n = 0; n < 60; ++n) {
    StepMaterialPoint(pt, L, dt);
    StepMaterialPoint(ref, L, dt);
    const Mat3 tau = Tau(pt);
    EXPECT_LE(tau(0, 0), 10e3 * (1 + 1e-10));
    if (RegionOf(pt) != McRegion::kTension) continue;
    if (cut_steps++ == 0) lateral_at_cut = tau(1, 1);
    EXPECT_NEAR(tau(0, 0), 10e3, 1e-9 * 10e3);
    EXPECT_NEAR(tau(1, 1), lateral_at_cut, 1e-9 * 10e3);
    EXPECT_NEAR(tau(2, 2), lateral_at_cut, 1e-9 * 10e3);
  }
  std::printf("MC uniaxial extension, t = 10 kPa: %d of 60 steps on the cut-off, tau_xx %.6e, "
              "tau_yy %.6e (nu/(1-nu) t = %.6e); without: tau_xx %.6e\n", cut_steps,
              Tau(pt)(0, 0), Tau(pt)(1, 1), 10e3 / 3, Tau(ref)(0, 0));
  EXPECT_GE(cut_steps, 45);
  EXPECT_NEAR(lateral_at_cut, 10e3 / 3, 0.05 * 10e3 / 3);  // nu/(1 - nu) = 1/3, finite strain
  EXPECT_GT(Tau(ref)(0, 0), 2 * 10e3);
}

// A 1 m tall block of cohesive soil (c = 50 kPa, phi = 30 deg: apex 86.6 kPa) hangs from a
// no-slip ceiling under gravity: the top carries rho g L = 19.6 kPa of tension. Without a cut-off
// it hangs (mean drop of millimetres); with t = 5 kPa the top fails in tension and the block falls.
Real HangingBlockDrop(const std::string& cutoff) {
  const std::string text =
      "name: hanging_block_2d\n"
      "dimension: 2\n"
      "time: {end: 0.6, cfl: 0.4}\n"
      "gravity: [0, -9.81]\n"
      "gravity_ramp: 0.2\n"
      "grid: {cell_size: 0.05}\n"
      "domain: {min: [0, 0], max: [1.0, 2.0], walls: {y-: slip, y+: no_slip}}\n"
      "materials:\n"
      "  soil: {model: mohr_coulomb, density: 2000, youngs_modulus: 5.0e6, poisson_ratio: 0.3, "
      "friction_angle_deg: 30, cohesion: 5.0e4" + cutoff + "}\n"
      "bodies:\n"
      "  - name: block\n"
      "    material: soil\n"
      "    region: {box: {min: [0.25, 1.0], max: [0.75, 2.0]}}\n"
      "    particles_per_cell: 2\n";
  LoadedScene scene = LoadSceneFromString(text, "hanging_block_2d.yaml");
  auto mean_y = [](const Particles& P) {
    Real m = 0, my = 0;
    for (size_t i = 0; i < P.size(); ++i) m += P.mass[i], my += P.mass[i] * P.x[i].y();
    return my / m;
  };
  const Real y0 = mean_y(scene.state.particles);
  testing::RunUntil(scene, 0.6, [](const State&, const StepReport&) {});
  return y0 - mean_y(scene.state.particles);
}

TEST(MohrCoulombCutoffTest, BlockHangingFromACeilingFallsOnlyWithTheCutoff) {
  const Real hangs = HangingBlockDrop(""), falls = HangingBlockDrop(", tension_cutoff: 5.0e3");
  std::printf("hanging block, 0.6 s: mean drop %.5f m without a cut-off, %.4f m with t = 5 kPa\n",
              hangs, falls);
  EXPECT_LT(hangs, 0.01);
  EXPECT_GT(falls, 0.2);
}

TEST(TrescaCutTest, CutStandsWithStrongClayAndCollapsesWithWeakClay) {
  const Real gamma = 2000 * 9.81;
  const CutRun strong = RunCut(gamma / 20e3, false), weak = RunCut(gamma / 2e3, false);
  std::printf("Tresca vertical cut H = 1 m, gamma = 19.6 kN/m^3, t = 1.2 s: s_u = 20 kPa: max dx "
              "%.4f m, mean speed %.4f m/s, max eps_p %.4f (%.1f s); s_u = 2 kPa: max dx %.3f m, "
              "mean speed %.3f m/s, max eps_p %.3f (%.1f s)\n", strong.max_dx, strong.mean_speed,
              strong.max_eps_p, strong.seconds, weak.max_dx, weak.mean_speed, weak.max_eps_p,
              weak.seconds);
  EXPECT_LT(strong.max_dx, 0.01);
  EXPECT_LT(strong.mean_speed, 0.01);
  EXPECT_GT(weak.max_dx, 0.2);
  EXPECT_GT(weak.max_eps_p, 0.1);
}

// Tension cracks lower the critical height of the cut (Terzaghi 1943, Theoretical Soil Mechanics:
// H_c = 4 s_u / gamma without and about 2.67 s_u / gamma with a tension crack; Chen's 3.83 is
// the upper bound without). With t = 0 the clay cannot carry the tension behind the crest. At
// gamma H / s_u = 3.2, between the two, the cut stands without a cut-off and collapses with
// t = 0; at 2.4, below 2.67, it also stands with t = 0 (a crack opens, the block stops).
TEST(TrescaCutTest, TensionCutoffLowersTheCriticalHeightToTheCrackedValue) {
  const CutRun plain = RunCut(3.2, false), cracked = RunCut(3.2, true), low = RunCut(2.4, true);
  std::printf("Tresca cut, t = 1.2 s: gamma H / s_u = 3.2: max dx %.4f m, speed %.4f m/s without a "
              "cut-off; %.3f m, %.3f m/s with t = 0; gamma H / s_u = 2.4 with t = 0: %.4f m, "
              "%.4f m/s\n", plain.max_dx, plain.mean_speed, cracked.max_dx, cracked.mean_speed,
              low.max_dx, low.mean_speed);
  EXPECT_LT(plain.max_dx, 0.01);
  EXPECT_LT(plain.mean_speed, 0.01);
  EXPECT_GT(cracked.max_dx, 0.2);
  EXPECT_LT(low.max_dx, 0.05);
  EXPECT_LT(low.mean_speed, 0.01);
}

}  // namespace
}  // namespace surge

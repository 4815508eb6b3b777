// Material-point verification (spec §2.10; issue 3): prescribed velocity gradients drive one
// particle through UpdateStress (materials/material_driver.h), with no grid.
//  J2 (Mast 2013 §3.5): every plastic return lands on the yield surface (1e-8 relative); rigid
//  rotations leave the invariants unchanged (1e-10); uniaxial tension follows the closed-form
//  hardening curve; unloading is elastic until reverse yield (Bauschinger shift 2/3 H per (3.71)).
//  Newtonian fluid (Mast 2013 (6.1)-(6.2)): pressure vs J, simple shear stress 2 mu d, Tait EOS.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "materials/friction_angles.h"
#include "materials/j2.h"
#include "materials/material_driver.h"
#include "materials/newtonian_fluid.h"
#include "materials/update_stress.h"
#include "support/random_paths.h"

namespace surge {
namespace {

// Aluminium-like parameters of the seed's Taylor bar (Table 7.1) with explicit hardening moduli.
J2Params Aluminium(Real isotropic, Real kinematic) {
  return J2Params{68.6e9, 23.3e9, 61e6, isotropic, kinematic};
}
Material J2Material(const J2Params& p) { return Material{"al", 2710.0, p}; }

Real YoungsModulus(const J2Params& p) {
  return 9 * p.bulk_modulus * p.shear_modulus / (3 * p.bulk_modulus + p.shear_modulus);
}

Mat3 Tau(const MaterialPoint& pt) { return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix(); }

Real YieldRadius(const J2Params& p, const History& h) {
  return std::sqrt(2.0 / 3.0) * (p.yield_stress + p.isotropic_hardening * h[kJ2PlasticStrain]);
}

// Stress invariants I1, J2 = 1/2 s:s, J3 = det s.
Vec3 Invariants(const Mat3& sigma) {
  const Mat3 s = Dev(sigma);
  return Vec3(sigma.trace(), 0.5 * s.squaredNorm(), s.determinant());
}

using testing::RandomL;

class J2DriverTest : public ::testing::TestWithParam<std::array<Real, 2>> {};

TEST_P(J2DriverTest, EveryPlasticStepEndsOnTheYieldSurface) {
  const J2Params p = Aluminium(GetParam()[0], GetParam()[1]);
  MaterialPoint pt = MakeMaterialPoint(J2Material(p));
  std::mt19937_64 rng(42);
  const Real dt = 1e-6, rate = 400;  // strain increments up to 4e-4, ~ 0.4 yield strains
  int plastic_steps = 0;
  Real worst = 0;
  for (int step = 0; step < 3000; ++step) {
    const Real alpha_before = pt.particles.history[0][kJ2PlasticStrain];
    StepMaterialPoint(pt, RandomL(rng, rate) + (step % 600 < 300 ? 1 : -1) * rate *
                                                    Vec3(1, -0.5, -0.5).asDiagonal().toDenseMatrix(),
                      dt);
    const History h = pt.particles.history.Get(0);
    const Real f = J2YieldFunction(p, Tau(pt), h);
    const Real radius = YieldRadius(p, h);
    if (h[kJ2PlasticStrain] > alpha_before) {
      ++plastic_steps;
      worst = std::max(worst, std::abs(f) / radius);
      ASSERT_LE(std::abs(f), 1e-8 * radius) << "step " << step;
    } else {
      ASSERT_LE(f, 1e-8 * radius) << "elastic step " << step << " outside the yield surface";
    }
  }
  std::printf("J2 k=%g H=%g: %d plastic steps of 3000, max |F|/radius = %.2e, alpha = %.4f\n",
              p.isotropic_hardening, p.kinematic_hardening, plastic_steps, worst,
              pt.particles.history[0][kJ2PlasticStrain]);
  EXPECT_GT(plastic_steps, 1000);
}

TEST_P(J2DriverTest, RigidRotationLeavesInvariantsUnchanged) {
  const J2Params p = Aluminium(GetParam()[0], GetParam()[1]);
  MaterialPoint pt = MakeMaterialPoint(J2Material(p));
  std::mt19937_64 rng(7);
  const Real dt = 1e-6;
  for (int step = 0; step < 200; ++step) StepMaterialPoint(pt, RandomL(rng, 400), dt);
  ASSERT_GT(pt.particles.history[0][kJ2PlasticStrain], 0) << "the point must be plastic";

  std::uniform_real_distribution<Real> angle(-3.0, 3.0);
  Real worst = 0;
  for (int r = 0; r < 20; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const Mat3 beta0 = J2BackStressOf(pt.particles.history.Get(0));
    const Real alpha0 = pt.particles.history[0][kJ2PlasticStrain];
    const Vec3 axis = Vec3(angle(rng), angle(rng), angle(rng)).normalized();
    const Mat3 R = Eigen::AngleAxis<Real>(angle(rng), axis).toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / dt, dt);  // f = I + dt L = R exactly

    const Real scale = sigma0.norm();
    const Vec3 i0 = Invariants(sigma0), i1 = Invariants(pt.particles.stress[0].matrix());
    const Vec3 tol = 1e-10 * Vec3(scale, scale * scale, scale * scale * scale);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(i1[i], i0[i], tol[i]) << "invariant " << i;
    EXPECT_LE((pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm(), 1e-10 * scale);
    const Mat3 beta1 = J2BackStressOf(pt.particles.history.Get(0));
    EXPECT_LE((beta1 - R * beta0 * R.transpose()).norm(), 1e-10 * scale);
    EXPECT_NEAR(pt.particles.history[0][kJ2PlasticStrain], alpha0, 1e-12 * alpha0);
    worst = std::max(worst, (pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm() / scale);
  }
  std::printf("J2 k=%g H=%g: rigid rotations, max |sigma - R sigma0 R^T| / |sigma0| = %.2e\n",
              p.isotropic_hardening, p.kinematic_hardening, worst);
}

// Uniaxial stress by mixed control (spec §2.10, Alawaji et al. 1992): the axial stretch is
// prescribed; the lateral rate L22 = L33 is iterated (secant) until sigma22 = 0.
void UniaxialStep(MaterialPoint& pt, Real stretch_ratio, Real dt, Real stress_tol) {
  const Real axial = (stretch_ratio - 1) / dt;  // f11 = 1 + dt L11 = stretch_ratio exactly
  auto lateral_stress = [&](Real x, MaterialPoint& trial) {
    trial = pt;
    StepMaterialPoint(trial, Vec3(axial, x, x).asDiagonal().toDenseMatrix(), dt);
    return trial.particles.stress[0].matrix()(1, 1);
  };
  MaterialPoint trial;
  Real x0 = -0.5 * axial, x1 = -0.3 * axial;
  Real s0 = lateral_stress(x0, trial), s1 = lateral_stress(x1, trial);
  for (int it = 0; it < 60 && std::abs(s1) > stress_tol && s1 != s0; ++it) {
    const Real x2 = x1 - s1 * (x1 - x0) / (s1 - s0);
    x0 = x1;
    s0 = s1;
    x1 = x2;
    s1 = lateral_stress(x1, trial);
  }
  ASSERT_LE(std::abs(s1), stress_tol);
  pt = trial;
}

// Closed form for uniaxial Kirchhoff stress at log strain eps with linear combined hardening:
// tau = sigma_Y + (k + H) eps_p and eps = tau/E + eps_p (coaxial, fixed axes: log strains add).
Real UniaxialTau(const J2Params& p, Real eps) {
  const Real E = YoungsModulus(p), kh = p.isotropic_hardening + p.kinematic_hardening;
  if (E * eps <= p.yield_stress) return E * eps;
  return (p.yield_stress + kh * eps) / (1 + kh / E);
}

// The mixed-control driver used by the soil tests (spec §2.10) reproduces the uniaxial curve:
// L11 prescribed, the other five symmetric components stress-controlled to zero.
TEST_P(J2DriverTest, MixedControlDriverReproducesUniaxialTension) {
  const J2Params p = Aluminium(GetParam()[0], GetParam()[1]);
  MaterialPoint pt = MakeMaterialPoint(J2Material(p));
  const Real dt = 1e-6, tol = 1e-9 * p.yield_stress;
  MixedControl c;
  c.stress_controlled = {false, true, true, true, true, true};
  Real worst = 0;
  int max_iterations = 0;
  for (int n = 0; n < 200; ++n) {
    const Real stretch = std::exp(0.05 / 200);  // log strain 0.05 in 200 steps
    c.L(0, 0) = (stretch - 1) / dt;
    const int iterations = MixedControlStep(pt, c, dt, tol);
    ASSERT_GE(iterations, 0) << "step " << n;
    max_iterations = std::max(max_iterations, iterations);
    const Real log_strain = std::log(pt.particles.F[0](0, 0));
    const Real exact = UniaxialTau(p, log_strain);
    worst = std::max(worst, std::abs(Tau(pt)(0, 0) - exact) / exact);
    ASSERT_NEAR(Tau(pt)(0, 0), exact, 1e-7 * exact) << "log strain " << log_strain;
    const Mat3& sigma = pt.particles.stress[0].matrix();
    ASSERT_LE((sigma - sigma(0, 0) * Vec3(1, 0, 0).asDiagonal().toDenseMatrix()).cwiseAbs().maxCoeff(), tol);
  }
  std::printf("J2 k=%g H=%g: mixed-control uniaxial, max rel. error %.2e, <= %d iterations\n",
              p.isotropic_hardening, p.kinematic_hardening, worst, max_iterations);
}

TEST_P(J2DriverTest, UniaxialTensionFollowsTheClosedFormCurve) {
  const J2Params p = Aluminium(GetParam()[0], GetParam()[1]);
  MaterialPoint pt = MakeMaterialPoint(J2Material(p));
  const Real dt = 1e-6, tol = 1e-10 * p.yield_stress;
  Real stretch = 1, worst = 0;
  const int steps = 200;
  for (int n = 0; n < steps; ++n) {
    const Real next = std::exp(0.05 * (n + 1) / steps);  // to 5 % log strain
    UniaxialStep(pt, next / stretch, dt, tol);
    stretch = next;
    const Real exact = UniaxialTau(p, std::log(stretch));
    const Real tau = Tau(pt)(0, 0);
    worst = std::max(worst, std::abs(tau - exact) / exact);
    ASSERT_NEAR(tau, exact, 1e-8 * exact) << "log strain " << std::log(stretch);
  }
  std::printf("J2 k=%g H=%g: uniaxial tension to 5 %% log strain, tau = %.6e Pa, max rel. error "
              "%.2e\n", p.isotropic_hardening, p.kinematic_hardening, Tau(pt)(0, 0), worst);

  // Unloading is elastic (d tau = E d eps, alpha fixed) down to the reverse yield stress
  // tau = 3/2 beta11 - (sigma_Y + k alpha) = H alpha - (sigma_Y + k alpha).
  const Real alpha = pt.particles.history[0][kJ2PlasticStrain];
  const Real E = YoungsModulus(p);
  const Real tau_peak = Tau(pt)(0, 0), eps_peak = std::log(stretch);
  const Real reverse = p.kinematic_hardening * alpha - (p.yield_stress + p.isotropic_hardening * alpha);
  EXPECT_NEAR(alpha, eps_peak - tau_peak / E, 1e-8 * alpha);
  const Real eps_end = eps_peak - 0.99 * (tau_peak - reverse) / E;
  for (int n = 1; n <= 50; ++n) {
    const Real next = std::exp(eps_peak + (eps_end - eps_peak) * n / 50);
    UniaxialStep(pt, next / stretch, dt, tol);
    stretch = next;
    EXPECT_EQ(pt.particles.history[0][kJ2PlasticStrain], alpha) << "unloading step " << n;
    EXPECT_NEAR(Tau(pt)(0, 0), tau_peak + E * (std::log(stretch) - eps_peak), 1e-8 * tau_peak);
  }
  // Past the reverse yield stress the point flows again, in compression, on the surface.
  for (int n = 1; n <= 20; ++n) {
    stretch *= std::exp(-0.01 * (tau_peak - reverse) / E);
    UniaxialStep(pt, std::exp(-0.01 * (tau_peak - reverse) / E), dt, tol);
  }
  EXPECT_GT(pt.particles.history[0][kJ2PlasticStrain], alpha);
  EXPECT_LE(std::abs(J2YieldFunction(p, Tau(pt), pt.particles.history.Get(0))),
            1e-8 * YieldRadius(p, pt.particles.history.Get(0)));
}

std::string HardeningName(const ::testing::TestParamInfo<std::array<Real, 2>>& info) {
  const bool iso = info.param[0] > 0;
  const bool kin = info.param[1] > 0;
  return iso && kin ? "Combined" : iso ? "Isotropic" : kin ? "Kinematic" : "Perfect";
}

INSTANTIATE_TEST_SUITE_P(Hardening, J2DriverTest,
                         ::testing::Values(std::array<Real, 2>{0.0, 0.0},      // perfect plasticity
                                           std::array<Real, 2>{2e9, 0.0},      // isotropic
                                           std::array<Real, 2>{0.0, 1.5e9},    // kinematic
                                           std::array<Real, 2>{2e9, 1.5e9}),   // combined
                         HardeningName);

// Stress power tau : d per reference volume, integrated with the trapezoid rule, against the
// stored energy psi (energy stage): equal while elastic, dissipation W - psi >= 0 once plastic.
TEST(J2DriverTest, StoredEnergyMatchesStressWorkAndDissipationIsPositive) {
  const J2Params p = Aluminium(2e9, 1.5e9);
  MaterialPoint pt = MakeMaterialPoint(J2Material(p));
  std::mt19937_64 rng(3);
  const Real dt = 1e-6, slow = 2.0, fast = 400.0;
  Real work = 0, worst_elastic = 0, min_dissipation = 0, psi_max = 0;
  for (int step = 0; step < 2000; ++step) {
    const Mat3 L = RandomL(rng, step < 1000 ? slow : fast);  // small (elastic), then plastic
    const Mat3 tau0 = Tau(pt);
    StepMaterialPoint(pt, L, dt);
    const Mat3 d = Sym(L);
    work += 0.5 * ((tau0 + Tau(pt)).array() * d.array()).sum() * dt;
    const Real psi = StrainEnergyDensity(pt.model.materials[0], pt.particles.F[0],
                                         pt.particles.stress[0].matrix(), pt.particles.strain[0]);
    psi_max = std::max(psi_max, psi);  // errors relative to the largest energy so far
    if (step < 1000) {
      ASSERT_EQ(pt.particles.history[0][kJ2PlasticStrain], 0) << "the slow phase must be elastic";
      worst_elastic = std::max(worst_elastic, std::abs(psi - work) / psi_max);
    } else {
      min_dissipation = std::min(min_dissipation, (work - psi) / psi_max);
    }
  }
  std::printf("J2 energy: elastic |psi - W| / psi_max <= %.2e; plastic (W - psi) / psi_max >= %.2e; "
              "final W - psi = %.4e J/m^3\n", worst_elastic, min_dissipation,
              work - StrainEnergyDensity(pt.model.materials[0], pt.particles.F[0],
                                         pt.particles.stress[0].matrix(), pt.particles.strain[0]));
  // f = I + dt L (2.18) is a first-order approximation of exp(dt L): the work differs from the
  // exact stress work by O(dt |L|) relative, hence the tolerances 10 dt |L|.
  EXPECT_LT(worst_elastic, 10 * dt * slow);
  EXPECT_GE(min_dissipation, -10 * dt * fast);
}

TEST(J2DriverTest, GeostaticStressIsReproducedByTheElasticState) {
  const J2Params p = Aluminium(0, 0);
  Mat3 sigma0 = Mat3::Zero();
  sigma0.diagonal() << -2e7, -2e7, -5e7;
  MaterialPoint pt = MakeMaterialPoint(J2Material(p), sigma0);
  StepMaterialPoint(pt, Mat3::Zero(), 1e-6);  // f = I: the stress must come back unchanged
  EXPECT_LE((pt.particles.stress[0].matrix() - sigma0).norm(), 1e-12 * sigma0.norm());
  EXPECT_EQ(pt.particles.history[0][kJ2PlasticStrain], 0);
}

// --- Newtonian fluid ---
Material Water(EquationOfState eos, Real viscosity) {
  NewtonianFluidParams p;
  p.bulk_modulus = 2.0e9;  // seed §6.1: k = 2.0 GPa, rho0 = 997.5 kg/m^3, mu = 0.001 Pa s
  p.viscosity = viscosity;
  p.equation_of_state = eos;
  p.tait_gamma = 7;
  return Material{"water", 997.5, p};
}

TEST(NewtonianFluidDriverTest, PressureFollowsKLnJ) {
  const Real mu = 1e-3, K = 2.0e9, dt = 1e-5;
  MaterialPoint pt = MakeMaterialPoint(Water(EquationOfState::kLinear, mu));
  Real worst = 0;
  for (int n = 0; n < 400; ++n) {
    const Real rate = n < 200 ? -10.0 : 12.0;  // compress to J ~ 0.94, then expand
    const Mat3 L = rate * Mat3::Identity();
    StepMaterialPoint(pt, L, dt);
    const Real J = pt.particles.F[0].determinant();
    const Mat3 sigma = pt.particles.stress[0].matrix();
    const Real expected = K * std::log(J) / J;  // (6.1) with theta = ln J, rho = rho0 / J
    worst = std::max(worst, std::abs(sigma.trace() / 3 - 2 * mu * rate - expected) / std::abs(expected));
    ASSERT_NEAR(sigma.trace() / 3 - 2 * mu * rate, expected, 1e-12 * std::abs(expected));
    // tau_m = J sigma_m = K ln J: the Hencky volumetric law.
    EXPECT_NEAR(J * (sigma.trace() / 3 - 2 * mu * rate), K * std::log(J), 1e-12 * K * std::abs(std::log(J)));
  }
  std::printf("fluid (linear EOS): max rel. error of sigma_m vs K ln J / J = %.2e\n", worst);
}

TEST(NewtonianFluidDriverTest, SimpleShearStressIsTwoMuD) {
  const Real mu = 0.5, gamma_dot = 40.0, dt = 1e-4;
  MaterialPoint pt = MakeMaterialPoint(Water(EquationOfState::kLinear, mu));
  Mat3 L = Mat3::Zero();
  L(0, 1) = gamma_dot;
  for (int n = 0; n < 100; ++n) {
    StepMaterialPoint(pt, L, dt);
    const Mat3& sigma = pt.particles.stress[0].matrix();
    // f = I + dt L is unimodular: J = 1, no pressure; d12 = gamma_dot / 2.
    EXPECT_NEAR(sigma(0, 1), 2 * mu * 0.5 * gamma_dot, 1e-12 * mu * gamma_dot);
    EXPECT_NEAR(sigma(1, 0), sigma(0, 1), 0);
    EXPECT_NEAR(sigma.diagonal().norm(), 0, 1e-3 * mu * gamma_dot);
  }
  std::printf("fluid simple shear: sigma12 = %.6f Pa (2 mu d12 = %.6f Pa)\n",
              pt.particles.stress[0].matrix()(0, 1), mu * gamma_dot);
}

TEST(NewtonianFluidDriverTest, TaitEquationOfState) {
  const Real K = 2.0e9, gamma = 7, B = K / gamma, dt = 1e-5;
  MaterialPoint pt = MakeMaterialPoint(Water(EquationOfState::kTait, 0));
  Real work = 0, worst = 0;  // work = int sigma_m dJ (trapezoid) against the stored energy
  Real J_prev = 1, sm_prev = 0;
  for (int n = 0; n < 300; ++n) {
    StepMaterialPoint(pt, -10.0 * Mat3::Identity(), dt);  // compress to J ~ 0.91
    const Real J = pt.particles.F[0].determinant();
    const Real sigma_m = pt.particles.stress[0].matrix().trace() / 3;
    const Real p = B * (std::pow(1 / J, gamma) - 1);  // p = B [(rho/rho0)^gamma - 1]
    worst = std::max(worst, std::abs(-sigma_m - p) / p);
    ASSERT_NEAR(-sigma_m, p, 1e-12 * p);
    work += 0.5 * (sigma_m + sm_prev) * (J - J_prev);
    J_prev = J;
    sm_prev = sigma_m;
  }
  const Real psi = StrainEnergyDensity(pt.model.materials[0], pt.particles.F[0],
                                       pt.particles.stress[0].matrix(), pt.particles.strain[0]);
  std::printf("fluid (Tait): J = %.4f, p = %.4e Pa, max rel. error %.2e, energy %.6e vs work %.6e\n",
              J_prev, -sm_prev, worst, psi, work);
  EXPECT_NEAR(psi, work, 1e-5 * psi);
  // The Tait law is stiffer than the linear one in compression and agrees to first order.
  const NewtonianFluidParams& tait = std::get<NewtonianFluidParams>(pt.model.materials[0].params);
  const Real small = 1 - 1e-6;
  EXPECT_NEAR(FluidMeanStress(tait, small), K * std::log(small) / small, 1e-5 * K * 1e-6);
}

// A run stores only the history slots its models declare (HistorySlotsOf, Particles::history's
// stride): each model with history is driven through a shear-and-compression path at the full
// stride of the material driver, and the slots at and above its declared count must stay zero,
// or the scene run would drop what the model wrote there.
TEST(HistorySlotsTest, EveryModelWritesOnlyItsDeclaredSlots) {
  const Real K = 1e7, G = 5e6;
  const FrictionCurve sand{20, 7750, 3.33e-7, 150, 20, 300};  // Mast 2013 Table 3.5 i
  MatsuokaNakaiParams mn_dp{K, G, 0, sand, false, MatsuokaNakaiPotential::kDruckerPrager};
  const std::vector<std::pair<const char*, MaterialParams>> models = {
      {"j2", J2Params{K, G, 1e4, 1e5, 1e5}},
      {"drucker_prager", DruckerPragerParams{K, G, 0.2, 0.1, 1e4, 1e5, 1e5}},
      {"drucker_prager_smooth_cap", SmoothCapDruckerPragerParams{K, G, 0.2, 1e4, 0.5}},
      {"modified_drucker_prager", ModifiedDruckerPragerParams{K, G, 0, sand, false}},
      {"matsuoka_nakai", MatsuokaNakaiParams{K, G, 0, sand, false}},
      {"matsuoka_nakai_dp_potential", mn_dp},
      {"mohr_coulomb", MohrCoulombParams{K, G, 0.5, 0.2, 1e4}},
      {"tresca", TrescaParams{K, G, 1e4}},
      {"snow", SnowParams{K, G, 1.0, 0.1, 0.5, 1.5e5}},
      {"bingham_fluid", BinghamFluidParams{K, 5, 200, 500}},
      {"frictional_fluid", FrictionalFluidParams{K, 5, 0.01, 10, 1e5}},
  };
  Mat3 L = Mat3::Zero();  // simple shear with compression [1/s]
  L(0, 1) = 2.0;
  L(1, 0) = 2.0;
  L(1, 1) = -0.5;
  for (const auto& [name, params] : models) {
    SCOPED_TRACE(name);
    const int slots = HistorySlotsOf(params);
    ASSERT_GE(slots, 1);
    ASSERT_LE(slots, kHistorySlots);
    MaterialPoint pt = MakeMaterialPoint(Material{name, 2000.0, params}, -1e5 * Mat3::Identity());
    ASSERT_EQ(pt.particles.history.stride(), kHistorySlots);  // the driver keeps every slot
    for (int step = 0; step < 200; ++step) {
      StepMaterialPoint(pt, L, 1e-3);
      for (int k = slots; k < kHistorySlots; ++k)
        ASSERT_EQ(pt.particles.history[0][k], 0.0) << "slot " << k << " at step " << step;
    }
    EXPECT_GT(pt.particles.history[0][kPlasticStrainSlot], 0.0) << "the path must be plastic";
  }
}

}  // namespace
}  // namespace surge

// Verification of the viscoplastic fluids (materials/bingham_fluid.h, frictional_fluid.h;
// Anura3D manual §7.2.2-7.2.3, (7.37) corrected, (7.38)) and of the viscous time-step limit
// (step/step.cpp, ViscousTimeStep).
//  Driver (one material point, no grid): steady simple shear tau = tau_y + mu_d gamma_dot above
//  the regularisation rate and mu_max gamma_dot below (1e-12); in random 3-D flows the
//  equivalent stress sqrt(J2) equals tau_y + mu_d ||D|| whenever yielded (1e-10) and the flow
//  stress is traceless; frictional fluid tau = c cos phi + p sin phi + mu_d gamma_dot under a
//  confining pressure, tau_y = c cos phi in tension; pressure vs J (linear and Tait EOS) and the
//  stored energy; objectivity under a superposed rigid motion (1e-12).
//  Viscous limit: the adaptive dt equals C rho0 dx^2 / (2 dim eta_L); a very viscous block runs
//  stably with it and blows up at a fixed dt well above it.
//  Engine (scenes/mudflow_2d.yaml, coarsened): a Bingham column slumps and stops; its runout
//  and wall height are within 30 % of the shallow-layer arrested state (Liu & Mei 1989), the
//  runout falls as tau_y rises, and a column with tau_y = rho g H does not collapse.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "materials/bingham_fluid.h"
#include "materials/frictional_fluid.h"
#include "materials/material_driver.h"
#include "materials/update_stress.h"
#include "support/run_scene.h"
#include "support/random_paths.h"

namespace surge {
namespace {

constexpr Real kPi = 3.14159265358979323846;

// Mud of scenes/mudflow_2d.yaml: rho = 1800, K = 1.6 MPa, mu_d = 5 Pa s, tau_y = 200 Pa.
BinghamFluidParams Mud(Real yield_stress = 200, Real max_viscosity = 500) {
  BinghamFluidParams p;
  p.bulk_modulus = 1.6e6;
  p.viscosity = 5;
  p.yield_stress = yield_stress;
  p.max_viscosity = max_viscosity;
  return p;
}

FrictionalFluidParams Granular(Real friction_deg, Real cohesion) {
  FrictionalFluidParams p;
  p.bulk_modulus = 1.6e6;
  p.viscosity = 1;
  p.friction_angle = friction_deg * kPi / 180;
  p.cohesion = cohesion;
  p.max_viscosity = 1e4;
  return p;
}

Mat3 SimpleShear(Real gamma_dot) {
  Mat3 L = Mat3::Zero();
  L(0, 1) = gamma_dot;  // v_x = gamma_dot y: d12 = gamma_dot / 2, ||D|| = gamma_dot
  return L;
}

// Equivalent shear stress sqrt(J2) = sqrt(1/2 s:s) [Pa]: sigma_12 in simple shear.
Real EquivalentShear(const Mat3& sigma) { return std::sqrt(0.5 * Dev(sigma).squaredNorm()); }

using testing::RandomL;

// --- driver tests --------------------------------------------------------------------------

TEST(BinghamFluidTest, SteadySimpleShearFollowsTheBiviscousFlowCurve) {
  const BinghamFluidParams p = Mud();
  const Real rate_c = p.yield_stress / (p.max_viscosity - p.viscosity);  // 0.404 1/s
  Real worst = 0;
  std::printf("Bingham simple shear (tau_y = %g Pa, mu_d = %g, mu_max = %g Pa s, "
              "gamma_dot_c = %.4f 1/s):\n", p.yield_stress, p.viscosity, p.max_viscosity, rate_c);
  for (Real rate : {0.01, 0.1, 0.3, 0.4, 0.41, 1.0, 10.0, 100.0, 1000.0}) {
    MaterialPoint pt = MakeMaterialPoint(Material{"mud", 1800, p});
    for (int n = 0; n < 10; ++n) StepMaterialPoint(pt, SimpleShear(rate), 1e-3);
    const Mat3& sigma = pt.particles.stress[0].matrix();
    const Real expected =
        rate > rate_c ? p.yield_stress + p.viscosity * rate : p.max_viscosity * rate;
    std::printf("  gamma_dot %8.3f 1/s: sigma_12 = %10.4f Pa (expected %10.4f), J - 1 = %.1e\n",
                rate, sigma(0, 1), expected, pt.particles.F[0].determinant() - 1);
    EXPECT_NEAR(sigma(0, 1), expected, 1e-12 * expected) << "gamma_dot " << rate;
    EXPECT_NEAR(sigma.diagonal().norm(), 0, 1e-9 * p.bulk_modulus);  // J = 1: no pressure
    worst = std::max(worst, std::abs(sigma(0, 1) - expected) / expected);
    // Yielded flow accumulates equivalent strain gamma_dot t / sqrt(3) (history slot 0).
    const Real strain = rate > rate_c ? 10 * 1e-3 * rate / std::sqrt(3.0) : 0;
    EXPECT_NEAR(pt.particles.history[0][kFluidYieldedStrain], strain, 1e-12 * (1 + strain));
  }
  std::printf("  max rel. error %.2e\n", worst);
}

TEST(BinghamFluidTest, YieldedFlowStressLiesOnTheDynamicYieldSurface) {
  // sqrt(J2) = tau_y + mu_d ||D|| whenever mu_eff < mu_max; sqrt(J2) <= mu_max ||D|| always;
  // the flow stress is traceless (no viscoplastic volume change: the fluid does not dilate).
  const BinghamFluidParams p = Mud();
  MaterialPoint pt = MakeMaterialPoint(Material{"mud", 1800, p});
  std::mt19937_64 rng(11);
  Real worst = 0;
  int yielded = 0, creeping = 0;
  for (int n = 0; n < 2000; ++n) {
    const Real scale = std::pow(10.0, -2.0 + 4.0 * (n % 100) / 100.0);  // 0.01 .. 100 1/s
    const Mat3 L = RandomL(rng, scale);
    StepMaterialPoint(pt, L, 1e-5);
    const Mat3& sigma = pt.particles.stress[0].matrix();
    const Real rate = ShearRateNorm(Sym(L));
    const Real q = EquivalentShear(sigma);
    const Real sigma_m = FluidMeanStress(EquationOfStateOf(p), pt.particles.F[0].determinant());
    ASSERT_NEAR(sigma.trace() / 3, sigma_m, 1e-12 * (std::abs(sigma_m) + q));
    if (p.viscosity * rate + p.yield_stress < p.max_viscosity * rate) {
      const Real target = p.yield_stress + p.viscosity * rate;
      ASSERT_NEAR(q, target, 1e-10 * target);
      worst = std::max(worst, std::abs(q - target) / target);
      ++yielded;
    } else {
      ASSERT_NEAR(q, p.max_viscosity * rate, 1e-10 * p.max_viscosity * rate);
      ASSERT_LE(q, p.yield_stress + p.viscosity * rate);
      ++creeping;
    }
  }
  std::printf("Bingham random 3-D flows: %d yielded steps, max |sqrt(J2) - (tau_y + mu_d ||D||)| "
              "/ target = %.2e; %d steps below the yield rate\n", yielded, worst, creeping);
  EXPECT_GT(yielded, 100);
  EXPECT_GT(creeping, 100);
}

TEST(FrictionalFluidTest, ShearUnderConfiningPressure) {
  for (Real cohesion : {0.0, 50.0}) {
    const FrictionalFluidParams p = Granular(30, cohesion);
    MaterialPoint pt = MakeMaterialPoint(Material{"sand", 1800, p});
    for (int n = 0; n < 10; ++n) StepMaterialPoint(pt, -1.0 * Mat3::Identity(), 1e-4);  // J < 1
    const Real J = pt.particles.F[0].determinant();
    const Real pressure = -p.bulk_modulus * std::log(J) / J;  // (6.1), tension positive
    for (Real rate : {1.0, 10.0, 100.0}) {
      MaterialPoint sheared = pt;
      StepMaterialPoint(sheared, SimpleShear(rate), 1e-4);  // isochoric: J unchanged
      const Real expected = cohesion * std::cos(p.friction_angle) +
                            pressure * std::sin(p.friction_angle) + p.viscosity * rate;
      const Mat3& sigma = sheared.particles.stress[0].matrix();
      std::printf("frictional fluid phi = 30 deg, c = %g Pa, p = %.2f Pa, gamma_dot = %g: "
                  "sigma_12 = %.6f Pa (c cos phi + p sin phi + mu_d gamma_dot = %.6f)\n",
                  cohesion, pressure, rate, sigma(0, 1), expected);
      EXPECT_NEAR(-sigma.trace() / 3, pressure, 1e-12 * pressure);
      EXPECT_NEAR(sigma(0, 1), expected, 1e-12 * expected);
    }
  }
  // In tension p = 0: the yield stress is c cos(phi) alone (spec §A.16.3 [REC]).
  const FrictionalFluidParams p = Granular(30, 50);
  MaterialPoint pt = MakeMaterialPoint(Material{"sand", 1800, p});
  for (int n = 0; n < 10; ++n) StepMaterialPoint(pt, 1.0 * Mat3::Identity(), 1e-4);  // J > 1
  StepMaterialPoint(pt, SimpleShear(10), 1e-4);
  EXPECT_GT(pt.particles.stress[0].matrix().trace(), 0);
  EXPECT_NEAR(pt.particles.stress[0].matrix()(0, 1), 50 * std::cos(p.friction_angle) + 10 * p.viscosity,
              1e-12 * 100);
}

TEST(ViscoplasticFluidTest, PressureFollowsTheEquationOfStateAndEnergyMatchesWork) {
  for (EquationOfState eos : {EquationOfState::kLinear, EquationOfState::kTait}) {
    BinghamFluidParams p = Mud();
    p.equation_of_state = eos;
    MaterialPoint pt = MakeMaterialPoint(Material{"mud", 1800, p});
    const Real K = p.bulk_modulus, B = K / p.tait_gamma;
    Real work = 0, J_prev = 1, sm_prev = 0, worst = 0;
    for (int n = 0; n < 300; ++n) {
      StepMaterialPoint(pt, (n < 200 ? -0.3 : 0.2) * Mat3::Identity(), 1e-3);
      const Real J = pt.particles.F[0].determinant();
      const Real sigma_m = pt.particles.stress[0].matrix().trace() / 3;
      const Real expected = eos == EquationOfState::kLinear ? K * std::log(J) / J  // (6.1)
                                                            : -B * (std::pow(J, -p.tait_gamma) - 1);
      ASSERT_NEAR(sigma_m, expected, 1e-12 * std::abs(expected));
      // Isotropic L: dev d = 0, no deviatoric stress even at mu_eff = mu_max.
      ASSERT_NEAR(EquivalentShear(pt.particles.stress[0].matrix()), 0, 1e-9 * std::abs(expected));
      worst = std::max(worst, std::abs(sigma_m - expected) / std::abs(expected));
      work += 0.5 * (sigma_m + sm_prev) * (J - J_prev);
      J_prev = J;
      sm_prev = sigma_m;
    }
    const Real psi = StrainEnergyDensity(pt.model.materials[0], pt.particles.F[0],
                                         pt.particles.stress[0].matrix(), pt.particles.strain[0]);
    std::printf("Bingham %s EOS: J = %.4f, sigma_m = %.2f Pa, max rel. error %.1e; energy %.4f "
                "vs work int sigma_m dJ %.4f J/m^3\n", eos == EquationOfState::kTait ? "Tait" : "linear",
                J_prev, sm_prev, worst, psi, work);
    EXPECT_NEAR(psi, work, 1e-4 * psi);
  }
}

TEST(ViscoplasticFluidTest, StressIsObjectiveUnderASuperposedRigidMotion) {
  // Observer B sees x' = Q x: F' = Q F, L' = Q L Q^T + Omega (Omega skew, the observer's spin).
  // The law depends on J and d = sym(L) only, so sigma' = Q sigma Q^T. Without spin this holds
  // for the whole stress (the step's f' = Q f Q^T, same J). With spin the deviatoric stress is
  // still exact; J then differs by O((dt |Omega|)^2) through the engine's incremental
  // f = I + dt L (Mast (2.18)), not through the fluid law, so the pressure is checked against
  // the EOS at B's own J.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<Real> u(-3.0, 3.0);
  Real worst = 0, worst_dev = 0;
  for (int model = 0; model < 2; ++model) {
    const Material mat = model == 0 ? Material{"mud", 1800, Mud()}
                                    : Material{"sand", 1800, Granular(30, 20)};
    MaterialPoint a = MakeMaterialPoint(mat);
    for (int n = 0; n < 50; ++n) StepMaterialPoint(a, RandomL(rng, 2.0), 1e-3);
    for (int r = 0; r < 20; ++r) {
      const Mat3 Q = Eigen::AngleAxis<Real>(u(rng), Vec3(u(rng), u(rng), u(rng)).normalized())
                         .toRotationMatrix();
      const Mat3 W = RandomL(rng, 50.0);
      const Mat3 omega = 0.5 * (W - W.transpose());
      const Mat3 L = RandomL(rng, r % 2 ? 0.05 : 5.0);  // below and above the yield rate
      MaterialPoint a1 = a, b = a, c = a;
      b.particles.F[0] = Q * a.particles.F[0];
      c.particles.F[0] = Q * a.particles.F[0];
      StepMaterialPoint(a1, L, 1e-3);
      StepMaterialPoint(b, Q * L * Q.transpose(), 1e-3);
      StepMaterialPoint(c, Q * L * Q.transpose() + omega, 1e-3);
      const Mat3 expected = Q * a1.particles.stress[0].matrix() * Q.transpose();
      const Real scale = a1.particles.stress[0].matrix().norm();
      const Real dev_scale = Dev(a1.particles.stress[0].matrix()).norm();
      EXPECT_LE((b.particles.stress[0].matrix() - expected).norm(), 1e-12 * scale);
      EXPECT_NEAR(b.particles.history[0][0], a1.particles.history[0][0], 1e-14);
      EXPECT_LE((Dev(c.particles.stress[0].matrix()) - Dev(expected)).norm(), 1e-12 * dev_scale);
      EXPECT_NEAR(c.particles.history[0][0], a1.particles.history[0][0], 1e-14);
      worst = std::max(worst, (b.particles.stress[0].matrix() - expected).norm() / scale);
      worst_dev = std::max(worst_dev, (Dev(c.particles.stress[0].matrix()) - Dev(expected)).norm() / dev_scale);
    }
  }
  std::printf("fluid objectivity: max |sigma' - Q sigma Q^T| / |sigma| = %.2e (rotated frame); "
              "with a superposed spin |Omega| ~ 50 1/s, deviatoric %.2e\n", worst, worst_dev);
}

// --- viscous time-step limit -----------------------------------------------------------------

// A block of viscous fluid (2-D, 0.2 x 0.2 m, dx = 0.02 m) resting on the floor of a box.
std::string ViscousBlock(const std::string& material) {
  return "name: viscous_block\n"
         "dimension: 2\n"
         "time: {end: 1.0, cfl: 0.4}\n"
         "gravity: [0, -9.81]\n"
         "grid: {cell_size: 0.02, shape_function: quadratic_bspline, transfer: apic, update: usl}\n"
         "domain: {min: [0, 0], max: [0.4, 0.3], walls: {x-: slip, x+: slip, y-: no_slip, "
         "y+: slip}}\n"
         "materials:\n  goo: " + material + "\n"
         "bodies:\n"
         "  - {name: block, material: goo, region: {box: {min: [0.1, 0], max: [0.3, 0.2]}}, "
         "particles_per_cell: 2}\n";
}

TEST(ViscousTimeStepTest, LimitMatchesTheFormula) {
  const Real rho = 1000, dx = 0.02, C = 0.4, dim = 2;
  {  // Newtonian: eta_L = 2 mu.
    LoadedScene s = LoadSceneFromString(
        ViscousBlock("{model: newtonian_fluid, density: 1000, bulk_modulus: 1e6, viscosity: 2000}"),
        "block.yaml");
    const Real expected = C * rho * dx * dx / (2 * dim * 2 * 2000);  // 1e-5 s
    const Real cfl = C * dx / std::sqrt(1e6 / rho);
    std::printf("viscous limit (newtonian, mu = 2000 Pa s): %.6e s (formula %.6e s), CFL %.3e s, "
                "step %.6e s\n", ViscousTimeStep(s.model, s.state), expected, cfl,
                NextTimeStep(s.model, s.state));
    EXPECT_NEAR(ViscousTimeStep(s.model, s.state), expected, 1e-12 * expected);
    EXPECT_NEAR(NextTimeStep(s.model, s.state), expected, 1e-12 * expected);
  }
  {  // Bingham: eta_L = 4/3 mu_max (1000 mu_d by default).
    LoadedScene s = LoadSceneFromString(
        ViscousBlock("{model: bingham_fluid, density: 1000, bulk_modulus: 1e6, viscosity: 0.2, "
                     "yield_stress: 50}"),
        "block.yaml");
    const Real expected = C * rho * dx * dx / (2 * dim * 4.0 / 3.0 * 200);
    EXPECT_NEAR(ViscousTimeStep(s.model, s.state), expected, 1e-12 * expected);
    EXPECT_NEAR(NextTimeStep(s.model, s.state), expected, 1e-12 * expected);
  }
  {  // Inviscid water: no limit; the CFL rule alone.
    LoadedScene s = LoadSceneFromString(
        ViscousBlock("{model: newtonian_fluid, density: 1000, bulk_modulus: 1e6, viscosity: 0}"),
        "block.yaml");
    EXPECT_TRUE(std::isinf(ViscousTimeStep(s.model, s.state)));
    EXPECT_NEAR(NextTimeStep(s.model, s.state), C * dx / std::sqrt(1e6 / rho), 1e-15);
  }
}

// Runs `steps` steps; returns the largest particle speed seen, or infinity once unhealthy.
Real MaxSpeedOver(LoadedScene& s, int steps) {
  const Pipeline pipeline = MakePipeline(s.model);
  Workspace work;
  StepReport report;
  Real vmax = 0;
  for (int n = 0; n < steps; ++n) {
    Step(s.model, pipeline, s.state, work, report);
    if (report.health.status != HealthStatus::kOk) return std::numeric_limits<Real>::infinity();
    for (const Vec3& v : s.state.particles.v) vmax = std::max(vmax, v.norm());
    if (!(vmax < 1e3)) return std::numeric_limits<Real>::infinity();
  }
  return vmax;
}

TEST(ViscousTimeStepTest, VeryViscousBlockIsStableWithTheLimitAndNotWithoutIt) {
  // mu = 2000 Pa s (a stiff paste): the viscous limit 1e-5 s is 16x below the CFL step. With it,
  // the block sags slowly (|v| << sqrt(g h) = 1.4 m/s); at a fixed dt of 10x the limit (still
  // below the CFL step) the explicit viscous term blows up; at 3x it is still stable (the
  // FTCS bound is conservative for quadratic B-splines, and C = 0.4 adds a 2.5x margin).
  const std::string goo =
      "{model: newtonian_fluid, density: 1000, bulk_modulus: 1e6, viscosity: 2000}";
  LoadedScene stable = LoadSceneFromString(ViscousBlock(goo), "block.yaml");
  const Real dt_v = ViscousTimeStep(stable.model, stable.state);
  const Real v_stable = MaxSpeedOver(stable, 5000);
  std::printf("viscous block, adaptive dt = %.3e s: t = %.3f s, max |v| = %.4f m/s\n", dt_v,
              stable.state.time, v_stable);
  EXPECT_LT(v_stable, 0.1);
  for (Real factor : {3.0, 10.0}) {
    LoadedScene fixed = LoadSceneFromString(ViscousBlock(goo), "block.yaml",
                                            {"time.fixed_dt=" + std::to_string(factor * dt_v)});
    const Real v = MaxSpeedOver(fixed, 1000);
    std::printf("viscous block, fixed dt = %4.0f x limit: max |v| over 1000 steps = %.4g m/s\n",
                factor, v);
    if (factor == 10.0) {
      EXPECT_TRUE(std::isinf(v)) << "expected the explicit viscous blow-up";
    }
  }
}

// --- engine: Bingham slump -------------------------------------------------------------------

constexpr Real kRho = 1800, kG = 9.81, kH = 0.4, kArea = 0.4 * 0.4;
constexpr Real kRateC = 0.4;  // regularisation rate gamma_dot_c ~ tau_y / mu_max [1/s]

struct Slump {
  Real front = 0;       // runout x_f at the end [m]
  Real wall_height = 0; // height of the free surface at the wall [m]
  Real front_speed_late = 0;   // mean front speed over the last 0.5 s [m/s]
  Real front_speed_early = 0;  // mean front speed over the first 0.5 s [m/s]
};

Real Front(const Particles& P, Real spacing) {
  Real front = 0;
  for (const Vec3& x : P.x) front = std::max(front, x.x());
  return front + 0.5 * spacing;
}

// scenes/mudflow_2d.yaml at dx = 0.04 m (400 particles), channel 2.6 m long, with yield stress
// tau_y and cap mu_max.
Slump RunSlump(Real yield_stress, Real max_viscosity, Real end) {
  LoadedScene s = LoadScene(testing::ScenePath("mudflow_2d.yaml"),
                            {"grid.cell_size=0.04", "domain.max=[2.6, 0.5]",
                             "materials.mud.yield_stress=" + std::to_string(yield_stress),
                             "materials.mud.max_viscosity=" + std::to_string(max_viscosity)});
  const Real spacing = s.model.dx / 2;
  Slump r;
  Real front_early = 0, front_late = 0;
  testing::RunUntil(s, end, [&](const State& st, const StepReport&) {
    if (front_early == 0 && st.time >= 0.5) front_early = Front(st.particles, spacing);
    if (front_late == 0 && st.time >= end - 0.5) front_late = Front(st.particles, spacing);
  });
  r.front = Front(s.state.particles, spacing);
  for (size_t p = 0; p < s.state.particles.size(); ++p) {
    if (s.state.particles.x[p].x() < s.model.dx) {
      r.wall_height = std::max(r.wall_height, s.state.particles.x[p].y() + 0.5 * spacing);
    }
  }
  r.front_speed_early = (front_early - kH) / 0.5;
  r.front_speed_late = (r.front - front_late) / 0.5;
  return r;
}

// Arrested shallow Bingham layer (Liu & Mei 1989, J. Fluid Mech. 207:505; Balmforth et al.
// 2007, J. Non-Newtonian Fluid Mech. 142:63): rho g h |dh/dx| = tau_y, h^2 = 2 B (x_f - x),
// B = tau_y / (rho g); the area A = (2/3) sqrt(2 B) x_f^(3/2) fixes x_f.
Real LubricationRunout(Real yield_stress) {
  const Real B = yield_stress / (kRho * kG);
  return std::pow(1.5 * kArea / std::sqrt(2 * B), 2.0 / 3.0);
}

TEST(BinghamSlumpTest, ColumnStopsNearTheYieldStressRunout) {
  // mu_max = tau_y / gamma_dot_c: the same regularisation rate for every tau_y.
  std::vector<Real> runouts;
  for (Real tau_y : {200.0, 400.0}) {
    const Slump r = RunSlump(tau_y, tau_y / kRateC, 2.0);
    const Real xf = LubricationRunout(tau_y);
    const Real h0 = std::sqrt(2 * tau_y / (kRho * kG) * xf);
    std::printf("Bingham slump tau_y = %5.0f Pa: runout %.3f m (shallow-layer %.3f m, %+.1f %%), "
                "wall height %.3f m (%.3f m, %+.1f %%); front speed %.3f m/s in the first 0.5 s, "
                "%.4f m/s in the last 0.5 s\n",
                tau_y, r.front, xf, 100 * (r.front - xf) / xf, r.wall_height, h0,
                100 * (r.wall_height - h0) / h0, r.front_speed_early, r.front_speed_late);
    EXPECT_NEAR(r.front, xf, 0.3 * xf);
    EXPECT_NEAR(r.wall_height, h0, 0.3 * h0);
    // Stopped up to the creep of the regularisation: below the yield rate gamma_dot_c the mud
    // shears at most at gamma_dot_c, so the front moves at most at about gamma_dot_c h_0.
    EXPECT_LT(r.front_speed_late, kRateC * h0) << "the slump has not stopped";
    EXPECT_LT(r.front_speed_late, 0.05 * r.front_speed_early);
    runouts.push_back(r.front);
  }
  EXPECT_GT(runouts[0], runouts[1]);
}

TEST(BinghamSlumpTest, ColumnWithYieldStressRhoGHStands) {
  // tau_y = rho g H > 2 x the critical-height bound tau_y > rho g H / 2 for a vertical cut
  // (Tresca c = tau_y in plane strain). The regularised fluid still creeps at sqrt(J2) / mu_max:
  // with mu_max = tau_y / 1 1/s the front may move by the creep bound
  // H * (rho g H / 2) / mu_max * t, far less than the collapse of a weaker column.
  const Real tau_y = kRho * kG * kH, end = 0.3;
  const Slump strong = RunSlump(tau_y, tau_y / 1.0, end);
  const Real weak = RunSlump(tau_y / 10, tau_y / 10 / kRateC, end).front;
  const Real creep = kH * 0.5 * kRho * kG * kH / (tau_y / 1.0) * end;
  std::printf("Bingham column tau_y = rho g H = %.0f Pa: front advance %.4f m in %.1f s (creep "
              "bound %.4f m); tau_y = rho g H / 10: %.4f m\n", tau_y, strong.front - kH, end, creep,
              weak - kH);
  EXPECT_LT(strong.front - kH, creep);
  EXPECT_LT(strong.front - kH, 0.1 * (weak - kH));
}

}  // namespace
}  // namespace surge

// Traditional two-surface Drucker-Prager (materials/drucker_prager.h; Mast 2013 §3.6.1, spec §2.5)
// at one material point (materials/material_driver.h):
//  - every return ends on the cone of the updated hardening (|F1| <= 1e-8 scale) or at the apex
//    (relative stress zero, I1 = apex of the updated alpha), with and without hardening;
//  - varrho_F = varrho_G = 0 reproduces the J2 model step for step (isotropic and kinematic
//    hardening) — the seed's "varrho_F = 0 recovers J2";
//  - rigid rotations are objective, back stress included;
//  - cone flow changes the volume by 3 varrho_G dgamma (zero for psi = 0, dilation for psi > 0);
//  - triaxial compression reaches the Mohr-Coulomb compression strength of (phi, c);
//  - hydrostatic tension of a cohesionless material returns to the stress-free apex;
//  - end to end from a scene file (engine, not driver): a 2-D block (half-width 1 m, height 2 m,
//    symmetry wall at x = 0, rough floor) under gravity stands with c = 20 kPa (critical height
//    of a vertical cut 4 c tan(45 + phi/2) / gamma = 7 m) and collapses into a heap with c = 0;
//    every particle stays admissible (cone and cutoff) after every step and the floor carries
//    the weight.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "materials/drucker_prager.h"
#include "materials/friction_angles.h"
#include "materials/j2.h"
#include "materials/material_driver.h"
#include "support/run_scene.h"
#include "support/random_paths.h"

namespace surge {
namespace {

// Soil-like elasticity (K = 20 MPa, G = 10 MPa); sigma_Y from (phi, c) as the scene does (3.107).
DruckerPragerParams Soil(Real phi_deg, Real psi_deg, Real c, Real k = 0, Real H = 0) {
  const Real phi = Radians(phi_deg);
  return DruckerPragerParams{20e6, 10e6, DruckerPragerSlope(phi), DruckerPragerSlope(Radians(psi_deg)),
                             -DruckerPragerCohesionTerm(c, phi) / std::sqrt(2.0 / 3.0), k, H};
}
Material Mat(const DruckerPragerParams& p) { return Material{"soil", 2000.0, p}; }
Mat3 Tau(const MaterialPoint& pt) { return pt.particles.F[0].determinant() * pt.particles.stress[0].matrix(); }
using testing::RandomL;

TEST(DruckerPragerTest, ReturnsEndOnTheConeOrAtTheApex) {
  struct Case {
    Real phi, psi, c, k, H;
  };
  for (const Case& cs : {Case{30, 0, 0, 0, 0}, Case{30, 10, 20e3, 0, 0}, Case{20, 5, 10e3, 2e6, 0},
                         Case{25, 0, 10e3, 1e6, 1e6}}) {
    const DruckerPragerParams p = Soil(cs.phi, cs.psi, cs.c, cs.k, cs.H);
    MaterialPoint pt = MakeMaterialPoint(Mat(p), -100e3 * Mat3::Identity());
    std::mt19937_64 rng(21);
    int cone = 0, apex = 0;
    Real worst = 0;
    for (int step = 0; step < 4000; ++step) {
      const Real alpha = pt.particles.history[0][kJ2PlasticStrain];
      const Real volume = pt.particles.history[0][kDpPlasticVolume];
      Mat3 L = RandomL(rng, 0.5);
      L -= L.trace() / 3.0 * Mat3::Identity();
      const Real sense = (step / 400) % 2 ? -1.0 : 1.0;
      L(0, 1) += sense * 2.0;
      L(1, 0) += sense * 2.0;
      if (step % 1000 >= 985) L += 50.0 * Mat3::Identity();  // stretch through the apex
      if (step % 1000 < 40) L -= 2.0 * Mat3::Identity();     // and back into compression
      StepMaterialPoint(pt, L, 1e-4);
      const History h = pt.particles.history.Get(0);
      const Mat3 tau = Tau(pt);
      const Real scale = std::max(tau.norm(), 1e3);
      if (h[kJ2PlasticStrain] == alpha && h[kDpPlasticVolume] == volume) continue;  // elastic
      const Real f = DruckerPragerYield(p, tau, h);
      const Real cutoff = DruckerPragerApex(p, h);
      if (std::abs(tau.trace() - cutoff) <= 1e-9 * scale) {  // on the tension cutoff
        ++apex;
        // Corner (cone active, alpha grew) or cutoff alone (inside the cone).
        if (h[kJ2PlasticStrain] > alpha) {
          ASSERT_LE(std::abs(f), 1e-8 * scale) << "corner, step " << step;
        } else {
          ASSERT_LE(f, 1e-8 * scale) << "cutoff, step " << step;
        }
        continue;
      }
      ++cone;
      worst = std::max(worst, std::abs(f) / scale);
      ASSERT_LE(std::abs(f), 1e-8 * scale) << "step " << step;
      ASSERT_LE(tau.trace(), cutoff + 1e-9 * scale);
    }
    std::printf("DP phi %g psi %g c %g k %g H %g: %d cone, %d apex returns, max |F1|/scale %.2e\n",
                cs.phi, cs.psi, cs.c, cs.k, cs.H, cone, apex, worst);
    EXPECT_GT(cone, 1000);
    EXPECT_GT(apex, 5) << "the stretches must reach the tension cutoff";
  }
}

TEST(DruckerPragerTest, ZeroFrictionIsJ2) {
  for (const auto& [k, H] : {std::pair<Real, Real>{0, 0}, {2e9, 0}, {0, 1.5e9}, {2e9, 1.5e9}}) {
    const J2Params j2{68.6e9, 23.3e9, 61e6, k, H};
    const DruckerPragerParams dp{68.6e9, 23.3e9, 0, 0, 61e6, k, H};
    MaterialPoint a = MakeMaterialPoint(Material{"al", 2710, j2});
    MaterialPoint b = MakeMaterialPoint(Material{"al", 2710, dp});
    std::mt19937_64 rng(42);
    Real worst = 0;
    for (int step = 0; step < 1000; ++step) {
      const Mat3 L = RandomL(rng, 400);
      StepMaterialPoint(a, L, 1e-6);
      StepMaterialPoint(b, L, 1e-6);
      worst = std::max(worst, (a.particles.stress[0].matrix() - b.particles.stress[0].matrix()).norm() /
                                  a.particles.stress[0].matrix().norm());
    }
    std::printf("DP with varrho = 0 vs J2 (k %g, H %g): max relative stress difference %.2e\n", k, H,
                worst);
    EXPECT_LE(worst, 1e-10);
    EXPECT_NEAR(b.particles.history[0][kJ2PlasticStrain], a.particles.history[0][kJ2PlasticStrain],
                1e-10 * a.particles.history[0][kJ2PlasticStrain]);
  }
}

TEST(DruckerPragerTest, RigidRotationIsObjective) {
  const DruckerPragerParams p = Soil(25, 5, 10e3, 1e6, 1e6);
  MaterialPoint pt = MakeMaterialPoint(Mat(p), -100e3 * Mat3::Identity());
  std::mt19937_64 rng(4);
  for (int step = 0; step < 200; ++step) {
    Mat3 L = RandomL(rng, 0.5);
    L -= L.trace() / 3.0 * Mat3::Identity();
    L(0, 1) += 2.0;
    L(1, 0) += 2.0;
    StepMaterialPoint(pt, L, 1e-4);
  }
  ASSERT_GT(pt.particles.history[0][kJ2PlasticStrain], 0);
  std::uniform_real_distribution<Real> u(-1.0, 1.0);
  for (int r = 0; r < 10; ++r) {
    const Mat3 sigma0 = pt.particles.stress[0].matrix();
    const Mat3 beta0 = J2BackStressOf(pt.particles.history.Get(0));
    const Mat3 R = Eigen::AngleAxis<Real>(3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized())
                       .toRotationMatrix();
    StepMaterialPoint(pt, (R - Mat3::Identity()) / 1e-4, 1e-4);
    EXPECT_LE((pt.particles.stress[0].matrix() - R * sigma0 * R.transpose()).norm(), 1e-10 * sigma0.norm());
    EXPECT_LE((J2BackStressOf(pt.particles.history.Get(0)) - R * beta0 * R.transpose()).norm(),
              1e-10 * sigma0.norm());
  }
}

TEST(DruckerPragerTest, ConeFlowChangesVolumeByTheDilationSlope) {
  for (const Real psi : {0.0, 10.0, 30.0}) {
    const DruckerPragerParams p = Soil(30, psi, 5e3);
    MaterialPoint pt = MakeMaterialPoint(Mat(p), -100e3 * Mat3::Identity());
    int plastic = 0;
    for (int step = 0; step < 300; ++step) {
      const Real alpha = pt.particles.history[0][kJ2PlasticStrain];
      const Real volume = pt.particles.history[0][kDpPlasticVolume];
      const Real lnJp = std::log(pt.particles.F[0].determinant()) -
                        0.5 * std::log(pt.particles.elastic_b[0].matrix().determinant());
      Mat3 L = Mat3::Zero();
      L(0, 1) = L(1, 0) = 0.5;
      StepMaterialPoint(pt, L, 1e-4);
      const Real dgamma = (pt.particles.history[0][kJ2PlasticStrain] - alpha) / std::sqrt(2.0 / 3.0);
      if (dgamma <= 0) continue;
      ++plastic;
      const Real dv = pt.particles.history[0][kDpPlasticVolume] - volume;
      EXPECT_NEAR(dv, 3 * p.dilation_slope * dgamma, 1e-12) << step;
      // The stored volume change is the kinematic one: ln J^p = ln J - tr(eps_e).
      const Real lnJp_new = std::log(pt.particles.F[0].determinant()) -
                            0.5 * std::log(pt.particles.elastic_b[0].matrix().determinant());
      EXPECT_NEAR(lnJp_new - lnJp, dv, 1e-9 * dgamma + 1e-14) << step;
    }
    EXPECT_GT(plastic, 200) << "psi " << psi;
  }
}

TEST(DruckerPragerTest, TriaxialCompressionAndApex) {
  for (const Real c : {0.0, 30e3}) {
    const Real phi = 30;
    MaterialPoint pt = MakeMaterialPoint(Mat(Soil(phi, 0, c)), -100e3 * Mat3::Identity());
    MixedControl m;
    m.stress_controlled = {false, true, true, true, true, true};
    m.target = -100e3 * Mat3::Identity();
    m.target(0, 0) = 0;
    for (int step = 0; step < 300; ++step) {
      m.L(0, 0) = -1.0;
      ASSERT_GE(MixedControlStep(pt, m, 1e-4, 1e-6), 0) << "step " << step;
    }
    const Mat3 tau = Tau(pt);
    const Real q = tau(1, 1) - tau(0, 0), pc = -tau.trace() / 3, s = std::sin(Radians(phi));
    const Real qf = 6 * s / (3 - s) * (pc + c / std::tan(Radians(phi)));
    std::printf("DP triaxial compression c = %g: q = %.6g Pa, MC q_f = %.6g Pa\n", c, q, qf);
    EXPECT_NEAR(q, qf, 1e-6 * qf);
  }
  MaterialPoint sand = MakeMaterialPoint(Mat(Soil(30, 0, 0)), -50e3 * Mat3::Identity());
  StepMaterialPoint(sand, 1.0 * Mat3::Identity(), 1e-2);  // 1 % stretch per axis
  EXPECT_EQ(sand.particles.stress[0].matrix().norm(), 0.0) << "cohesionless apex is stress-free";
}

// Scene of the block: the cohesion is spliced in; gravity ramps over 0.3 s (seed App. B.2.3).
std::string BlockScene(Real cohesion) {
  return R"(name: dp_block
dimension: 2
time: {end: 2.0, cfl: 0.4}
gravity: [0, -9.81]
gravity_ramp: 0.3
grid: {cell_size: 0.1, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [4, 2.5]
  walls: {x-: slip, x+: slip, y-: {friction: 0.6}}
materials:
  soil: {model: drucker_prager, density: 2000, bulk_modulus: 5e6, shear_modulus: 3e6,
         friction_angle_deg: 30, dilation_angle_deg: 0, cohesion: )" +
         std::to_string(cohesion) + R"(}
bodies:
  - name: block
    material: soil
    region: {box: {min: [0, 0], max: [1, 2]}}
    particles_per_cell: 2
)";
}

TEST(DruckerPragerTest, SceneBlockStandsWithCohesionAndCollapsesWithout) {
  for (const Real c : {20e3, 0.0}) {
    LoadedScene scene = LoadSceneFromString(BlockScene(c), "dp_block.yaml");
    const auto& p = std::get<DruckerPragerParams>(scene.model.materials[0].params);
    const Real weight = [&] {
      Real m = 0;
      for (const Real mp : scene.state.particles.mass) m += mp;
      return m * 9.81;  // per metre of the plane-strain slab
    }();
    Real worst = 0, kinetic_peak = 0, kinetic = 0, floor = 0;
    int samples = 0;
    testing::RunUntil(scene, 2.0, [&](const State& s, const StepReport& r) {
      const Particles& P = s.particles;
      kinetic = 0;
      for (size_t i = 0; i < P.size(); ++i) {
        kinetic += 0.5 * P.mass[i] * P.v[i].squaredNorm();
        const Mat3 tau = P.F[i].determinant() * P.stress[i].matrix();
        const Real scale = std::max(tau.norm(), 1e3);
        // Admissible: inside the cone (3.84) and below the cutoff (3.93).
        worst = std::max(worst, DruckerPragerYield(p, tau, P.history.Get(i)) / scale);
        worst = std::max(worst, (tau.trace() - DruckerPragerApex(p, P.history.Get(i))) / scale);
      }
      kinetic_peak = std::max(kinetic_peak, kinetic);
      if (s.time >= 1.5) {
        floor += -r.walls.force[int(Face::kYMin)].y();
        ++samples;
      }
    });
    floor /= samples;
    const Particles& P = scene.state.particles;
    Real front = 0, top = 0, alpha_max = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      front = std::max(front, P.x[i].x());
      top = std::max(top, P.x[i].y());
      alpha_max = std::max(alpha_max, P.history[i][kJ2PlasticStrain]);
    }
    std::printf("DP scene block c = %g Pa: front %.3f m (was 1), top %.3f m (was 2), max "
                "plastic strain %.3g, max F/scale %.2e, kinetic end/peak %.2e, floor %.5g N/m "
                "(weight %.5g)\n",
                c, front, top, alpha_max, worst, kinetic / kinetic_peak, floor, weight);
    EXPECT_LE(worst, 1e-8) << "a particle left the admissible region";
    EXPECT_NEAR(floor, weight, 0.03 * weight);
    if (c > 0) {  // stands: a bulge below a quarter cell, settles elastically
      EXPECT_LT(front, 1.0 + 0.05);
      EXPECT_GT(top, 2.0 - 0.1);
    } else {  // a cohesionless vertical face cannot stand: it slumps into a heap
      EXPECT_GT(front, 1.5);
      EXPECT_LT(top, 1.8);
      EXPECT_GT(alpha_max, 0.05);
      EXPECT_LT(kinetic, 1e-2 * kinetic_peak) << "the heap must come to rest";
    }
  }
}

}  // namespace
}  // namespace surge

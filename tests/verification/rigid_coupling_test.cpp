// Two-way coupling of dynamic obstacles (Bullet) with the MPM (issue #5): a light box dropped
// into water floats in force balance (its Archimedes draft d = (rho_box / rho_water) H is not
// reached yet: see the known gap below); a dense box sinks to the floor and rests there (Bullet
// contact with the domain wall); and a box far from any material falls freely under the
// (ramped) gravity the coupling applies.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

// A 3-D slab two cells thick between slip walls (z): water 0.16 m deep in a 0.6 m tank, and a
// 0.2 m wide, 0.1 m high box spanning the slab, released with its bottom on the water surface.
// (A square section at half the water's density would capsize: a rectangular prism floats
// upright only for width / height > sqrt(6 s (1 - s)) = 1.22 at s = 0.5.)
std::string FloatScene(Real box_density, Real dx = 0.02, const std::string& antilocking = "node") {
  const std::string slab = std::to_string(2 * dx);  // two cells thick
  return R"(name: floating_box
dimension: 3
time: {end: 1.6, cfl: 0.3}
gravity: [0, -9.81, 0]
gravity_ramp: 0.1
grid: {cell_size: )" + std::to_string(dx) + R"(, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0, 0]
  max: [0.6, 0.4, )" + slab + R"(]
  walls: {x-: slip, x+: slip, y-: slip, z-: slip, z+: slip}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e5, viscosity: 0.01,
          antilocking: {method: )" + antilocking + R"(}}
bodies:
  - name: water
    material: water
    region: {box: {min: [0, 0, 0], max: [0.6, 0.16, )" + slab + R"(]}}
    particles_per_cell: 2
obstacles:
  - name: box
    shape: {box: {min: [0.2, 0.16, 0], max: [0.4, 0.26, )" + slab + R"(]}}
    motion: {dynamic: {density: )" + std::to_string(box_density) + R"(}}
)";
}

struct Floating {
  Real draft, expected, force, weight;
};

Floating FloatingBox(Real dx, const std::string& antilocking) {
  constexpr Real kRhoW = 1000, kRhoB = 500, kH = 0.1, kWidth = 0.2, kTank = 0.6;
  const Real kSlab = 2 * dx;
  LoadedScene scene = LoadSceneFromString(FloatScene(kRhoB, dx, antilocking), "floating_box.yaml");
  const Real water_mass = testing::TotalMass(scene.state.particles);
  const Real water_area = water_mass / (kRhoW * kSlab);  // incompressible water cross-section
  Real bottom = 0, force_y = 0;
  int n = 0;
  Real tilt = 0;
  testing::RunUntil(scene, 1.6, [&](const State& s, const StepReport& r) {
    tilt = std::max(tilt, std::acos(std::min(Real(1), s.rigid.at(0).rotation(1, 1))));
    if (s.time < 1.1) return;
    bottom += s.rigid.at(0).position.y() - 0.5 * kH;  // reference point = box centre
    force_y += r.obstacles.at(0).force.y();            // the water's push on the box, upward
    ++n;
  });
  bottom /= n;
  force_y /= n;
  const Real deepest = -testing::MaxPenetration(scene);
  std::printf("deepest particle inside the box at the end %.3g m; largest tilt %.2e rad\n",
              -deepest, tilt);
  // Explicit coupling: the contact saw the body at t_n, so particles may lie v dt inside its
  // pose at t_{n+1}; the next step's contact and projection take them out.
  EXPECT_LT(-deepest, 1e-4 * dx);
  EXPECT_LT(tilt, 1e-3);  // a stable section (width / height 2) stays upright
  // Surface level h_s with the box in it: (tank - width) h_s + width y_b = water area.
  const Real surface = (water_area - kWidth * bottom) / (kTank - kWidth);
  const Real draft = surface - bottom, expected = kRhoB / kRhoW * kH;
  const Real weight = kRhoB * kH * kWidth * kSlab * 9.81;
  std::printf("floating box (h = %g m, anti-locking %s): draft %.5f m, Archimedes %.5f m (error "
              "%+.2f %%); mean water force %.4f N, weight %.4f N (%+.2f %%); box bottom %.4f m, "
              "surface %.4f m\n",
              dx, antilocking.c_str(), draft, expected, 100 * (draft / expected - 1), force_y,
              weight, 100 * (force_y / weight - 1), bottom, surface);
  return {draft, expected, force_y, weight};
}

// KNOWN GAP (issue #5 asks for the draft within 3 %): at h = 0.02 m (2.5 cells of draft) the
// box floats 11 % too deep without anti-locking (26 % before off-grid faces kept their edge
// nodes, commit 8d561b8). The coupling is not the cause: a fixed box held at the same depth gets
// the same upward force. The water's force on a downward-facing face (a lid) is low at coarse
// resolution: a pressure offset of the water under the box that depends on the structures and
// passages around it, plus the face's sub-cell offset; it converges (2-D lids within 1.2 % at
// 20 cells of depth; docs/validation.md). Until the coarse case is fixed this test holds the
// coupling to what it does right (force balance, no penetration, no tilt) and the draft to the
// measured error band, so that a regression or a fix both show.
TEST(RigidCouplingTest, LightBoxFloatsInForceBalanceWithTheKnownLidForceDeficit) {
  const Floating f = FloatingBox(0.02, "none");
  EXPECT_NEAR(f.force, f.weight, 0.03 * f.weight);  // at rest the water carries the box
  EXPECT_GT(f.draft, f.expected);                    // deeper than Archimedes (the known gap)
  EXPECT_LT(f.draft, 1.2 * f.expected);              // measured +11 %
}

// The draft error against resolution and anti-locking (about 3 min; run by hand with
// --gtest_also_run_disabled_tests --gtest_filter=*Resolution*). Measured 2026-11-23 before
// commit 8d561b8: h = 0.02 node +57 %, none +26 %; h = 0.01 none +27 %, node +48 %.
TEST(RigidCouplingTest, DISABLED_FloatingBoxResolution) {
  FloatingBox(0.02, "node");
  FloatingBox(0.02, "none");
  FloatingBox(0.01, "none");
  FloatingBox(0.01, "node");
}

TEST(RigidCouplingTest, DenseBoxSinksAndRestsOnTheFloor) {
  LoadedScene scene = LoadSceneFromString(FloatScene(3000), "sinking_box.yaml");
  testing::RunUntil(scene, 1.2, [](const State&, const StepReport&) {});
  const RigidBodyState& b = scene.state.rigid.at(0);
  std::printf("sinking box: bottom at %.4f m, speed %.2e m/s after 1.2 s\n",
              b.position.y() - 0.05, b.velocity.norm());
  EXPECT_NEAR(b.position.y() - 0.05, 0.0, 0.005);  // on the floor (Bullet contact with the wall)
  EXPECT_LT(b.velocity.norm(), 0.02);
}

TEST(RigidCouplingTest, BoxFallsFreelyUnderTheRampedGravity) {
  // A body far from the material only feels the ramped gravity of the MPM (seed App. B.2.3):
  // y(t) follows the step-by-step integral of g min(t / t_r, 1).
  const std::string text = R"(name: free_box
dimension: 3
time: {end: 0.3, fixed_dt: 1.0e-3}
gravity: [0, -9.81, 0]
gravity_ramp: 0.1
grid: {cell_size: 0.05}
domain: {min: [0, 0, 0], max: [2, 2, 2]}
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies:
  - {name: pebble, material: rubber, region: {box: {min: [0.1, 0.1, 0.1], max: [0.2, 0.2, 0.2]}}}
obstacles:
  - name: box
    shape: {box: {min: [1.0, 1.5, 1.0], max: [1.2, 1.7, 1.2]}}
    motion: {dynamic: {mass: 3.0, velocity: [0.5, 0, 0]}}
)";
  LoadedScene scene = LoadSceneFromString(text, "free_box.yaml");
  testing::RunUntil(scene, 0.3, [](const State&, const StepReport&) {});
  // Semi-implicit Euler with the ramped gravity: v_{k+1} = v_k + g(t_k) dt, y_{k+1} = y_k + v_{k+1} dt.
  Real v = 0, y = 1.6;
  for (int k = 0; k < 300; ++k) {
    const Real t = k * 1e-3;
    v += -9.81 * std::min(t / 0.1, 1.0) * 1e-3;
    y += v * 1e-3;
  }
  const RigidBodyState& b = scene.state.rigid.at(0);
  std::printf("free box: y %.9f m (integral %.9f), x %.6f m (0.5 m/s x 0.3 s + 1.1 = 1.25)\n",
              b.position.y(), y, b.position.x());
  EXPECT_NEAR(b.position.y(), y, 1e-9);
  EXPECT_NEAR(b.position.x(), 1.25, 1e-9);
}

}  // namespace
}  // namespace surge

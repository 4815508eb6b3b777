// Two-way coupling of dynamic obstacles (Bullet) with the MPM (issue #5): a light box dropped
// into water floats in force balance, a few per cent deeper than its Archimedes draft
// d = (rho_box / rho_water) H at the resolutions a test can afford (see the known gap below); a
// dense box sinks to the floor and rests there (Bullet contact with the domain wall); and a box
// far from any material falls freely under the (ramped) gravity the coupling applies.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

// A tank for a floating box: a 3-D slab `slab_cells` thick between slip walls (z), water `water`
// deep in a tank `tank` wide, and a box `width` x `height` spanning the slab, centred, released
// at rest with its bottom on the water surface. The defaults are the coarse tank of the
// regression test: water 0.16 m deep in a 0.6 m tank, a 0.2 m wide, 0.1 m high box. (A square
// section at half the water's density would capsize: a rectangular prism floats upright only for
// width / height > sqrt(6 s (1 - s)) = 1.22 at s = 0.5.)
struct Tank {
  Real dx = 0.02;                       // cell size h [m]
  Real width = 0.2, height = 0.1;       // box section [m]
  Real tank = 0.6, water = 0.16;        // tank width, initial water depth [m]
  Real bulk = 2.0e5, viscosity = 5.0;   // water: K [Pa], mu [Pa s] (see FloatingBox)
  Real end = 2.0, average_from = 1.5;   // run end and start of the averaging window [s]
  std::string antilocking = "none";
  int slab_cells = 2;                   // slab thickness along z [cells]
  std::string ghosts = "mirror";        // domain.ghost_nodes
  std::string faces = "interpolated";   // the box's contact.faces
  bool shifting = false;                // the water's particle_shifting
  Real creep_from = -1;                 // if >= 0: also the mean bottom over [creep_from, +0.5 s]
  Real max_tilt = 1e-3;                 // [rad]: a stable section (width / height 2) stays upright
  Real max_inside = 1e-4;               // deepest particle inside the box at the end [h]
};

std::string FloatScene(const Tank& t, Real box_density) {
  auto s = [](Real v) { return std::to_string(v); };
  const std::string slab = s(t.slab_cells * t.dx);
  const Real x0 = 0.5 * (t.tank - t.width);
  return R"(name: floating_box
dimension: 3
time: {end: )" + s(t.end) + R"(, cfl: 0.3}
gravity: [0, -9.81, 0]
gravity_ramp: 0.1
grid: {cell_size: )" + s(t.dx) + R"(, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0, 0]
  max: [)" + s(t.tank) + ", 0.4, " + slab + R"(]
  walls: {x-: slip, x+: slip, y-: slip, z-: slip, z+: slip}
  ghost_nodes: )" + t.ghosts + R"(
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: )" + s(t.bulk) +
         ", viscosity: " + s(t.viscosity) + R"(,
          antilocking: {method: )" + t.antilocking + R"(}, particle_shifting: )" +
         (t.shifting ? "true" : "false") + R"(}
bodies:
  - name: water
    material: water
    region: {box: {min: [0, 0, 0], max: [)" + s(t.tank) + ", " + s(t.water) + ", " + slab + R"(]}}
    particles_per_cell: 2
obstacles:
  - name: box
    shape: {box: {min: [)" + s(x0) + ", " + s(t.water) + R"(, 0], max: [)" + s(x0 + t.width) +
         ", " + s(t.water + t.height) + ", " + slab + R"(]}}
    motion: {dynamic: {density: )" + s(box_density) + R"(}}
    contact: {faces: )" + t.faces + R"(}
)";
}

// The coarse tank with water of viscosity 0.01 Pa s and node anti-locking (the sinking box).
std::string FloatScene(Real box_density) {
  Tank t;
  t.viscosity = 0.01;
  t.antilocking = "node";
  return FloatScene(t, box_density);
}

struct Floating {
  Real draft;       // box bottom below the open water's surface [m]
  Real draft_tank;  // below the surface that the whole tank's water mass gives [m]
  Real draft_visible;  // below the visible surface (top particles of the open columns + h / 4) [m]
  Real expected;    // Archimedes [m]
  Real force, weight;  // mean water force on the box and its weight [N]
  Real creep;       // mean bottom over the averaging window minus over Tank::creep_from's [m]
};

// Drops a box of half the water's density into the tank and measures its draft against
// Archimedes, averaged over [average_from, end]. The viscosity (5 Pa s by default) only damps
// the heave (at rest the viscous stress is zero, so the equilibrium is that of any fluid): with
// 0.01 Pa s the box still swings by +-5 mm after 1 s at h = 0.0125 m. The water is slightly
// compressible (sigma_m = (K/J) ln J, so rho / rho0 - 1 = p / K to first order, c = rho0 g / K):
//  - the box's buoyancy per area is int_0^d rho g dz = rho0 g (d + c d^2 / 2), so Archimedes
//    gives d_A = d0 (1 - c d0 / 2), d0 = (rho_b / rho_w) H;
//  - the surface s of the open water (the columns beside the box, tank - width wide) follows
//    from their mass per area m = rho0 (s + c s^2 / 2).
// Archimedes compares the box with the water around it, so the draft is taken from the open
// water. The surface that the whole tank's mass gives (box bottom y_b:
// M / (rho0 b) = (tank - width) s + width y_b + c ((tank - width) s^2 / 2 + width (s y_b -
// y_b^2 / 2))) reads too high: the particles under the box crowd (their mass per volume exceeds
// rho0 / J by 1-5 % at h = 0.02 m, 11 % in a tight tank at h = 0.04 m), so that water fills less
// height than its mass says. The visible surface (top particle of each open column + h / 4) is
// printed as a check of the open-water surface.
Floating FloatingBox(const Tank& t) {
  constexpr Real kRhoW = 1000, kRhoB = 500, kG = 9.81;
  const Real slab = t.slab_cells * t.dx, open = t.tank - t.width, c = kRhoW * kG / t.bulk;
  LoadedScene scene = LoadSceneFromString(FloatScene(t, kRhoB), "floating_box.yaml");
  const Real water_mass = testing::TotalMass(scene.state.particles);
  Real bottom = 0, force_y = 0, open_mass = 0, visible = 0, tilt = 0, early = 0;
  int n = 0, n_early = 0;
  const int bins = int(std::lround(t.tank / (0.5 * t.dx)));  // columns h / 2 wide
  std::vector<Real> top(static_cast<size_t>(bins));
  const auto started = std::chrono::steady_clock::now();
  testing::RunUntil(scene, t.end, [&](const State& s, const StepReport& r) {
    const RigidBodyState& b = s.rigid.at(0);
    tilt = std::max(tilt, std::acos(std::min(Real(1), b.rotation(1, 1))));
    if (t.creep_from >= 0 && s.time >= t.creep_from && s.time < t.creep_from + 0.5) {
      early += b.position.y() - 0.5 * t.height;
      ++n_early;
    }
    if (s.time < t.average_from) return;
    bottom += b.position.y() - 0.5 * t.height;  // reference point = box centre
    force_y += r.obstacles.at(0).force.y();     // the water's push on the box, upward
    const Real x0 = b.position.x() - 0.5 * t.width, x1 = x0 + t.width;
    std::fill(top.begin(), top.end(), Real(0));
    const Particles& P = s.particles;
    for (size_t p = 0; p < P.size(); ++p) {
      const Real x = P.x[p].x();
      if (x >= x0 && x <= x1) continue;  // under the box
      open_mass += P.mass[p];
      const size_t col = size_t(std::clamp(int(x / (0.5 * t.dx)), 0, bins - 1));
      top[col] = std::max(top[col], P.x[p].y());
    }
    Real sum = 0;
    int cols = 0;
    for (int k = 0; k < bins; ++k) {
      const Real xc = (k + 0.5) * 0.5 * t.dx;
      if (xc > x0 && xc < x1) continue;
      sum += top[size_t(k)];
      ++cols;
    }
    visible += sum / cols + 0.25 * t.dx;  // a particle stands for h / 2 of height
    ++n;
  });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  bottom /= n;
  force_y /= n;
  visible /= n;
  open_mass /= n;
  const Real deepest = -testing::MaxPenetration(scene);
  std::printf("deepest particle inside the box at the end %.3g m; largest tilt %.2e rad\n",
              -deepest, tilt);
  // Explicit coupling: the contact saw the body at t_n, so particles may lie v dt inside its
  // pose at t_{n+1}; the next step's contact and projection take them out.
  EXPECT_LT(-deepest, t.max_inside * t.dx);
  EXPECT_LT(tilt, t.max_tilt);
  // Open water: m = rho0 (s + c s^2 / 2), fixed point (c s / 2 < 1 %).
  const Real per_area = open_mass / (kRhoW * slab * open);
  Real surface = per_area;
  for (int k = 0; k < 20; ++k) surface = per_area - c * surface * surface / 2;
  // Whole tank, the same way.
  const Real area = water_mass / (kRhoW * slab);
  Real tank_surface = (area - t.width * bottom) / open;
  for (int k = 0; k < 20; ++k) {
    const Real depth_area = open * tank_surface * tank_surface / 2 +
                            t.width * (tank_surface * bottom - bottom * bottom / 2);
    tank_surface = (area - c * depth_area - t.width * bottom) / open;
  }
  const Real d0 = kRhoB / kRhoW * t.height, expected = d0 * (1 - c * d0 / 2);
  const Real weight = kRhoB * t.height * t.width * slab * kG;
  const Real draft = surface - bottom, draft_tank = tank_surface - bottom;
  auto err = [&](Real d) { return 100 * (d / expected - 1); };
  std::printf("floating box (h = %g m, %.2f cells per draft, anti-locking %s, mu %g Pa s, slab %d "
              "cells, ghost nodes %s%s): draft "
              "%.5f m below the open water (error %+.2f %%; visible surface %+.2f %%; whole "
              "tank's mass %+.2f %%), Archimedes %.5f m; mean water force %.4f N, weight %.4f N "
              "(%+.2f %%); box bottom %.4f m; %.1f s\n",
              t.dx, expected / t.dx, t.antilocking.c_str(), t.viscosity, t.slab_cells,
              t.ghosts.c_str(), t.shifting ? ", particle shifting" : "", draft, err(draft),
              err(visible - bottom), err(draft_tank), expected, force_y, weight,
              100 * (force_y / weight - 1), bottom, seconds);
  const Real creep = n_early > 0 ? bottom - early / n_early : 0;
  if (n_early > 0)
    std::printf("  bottom moved %+.2f mm from the window at %.1f s to the last one\n", 1e3 * creep,
                t.creep_from);
  return {draft, draft_tank, visible - bottom, expected, force_y, weight, creep};
}

// KNOWN GAP (issue #5 asks for the draft within 3 %): at h = 0.02 m (2.5 cells of draft) the
// box floats 4.32 % deeper than Archimedes (2026-12-02, with the obstacles' gap test and
// interpolated faces, docs/obstacle-faces.md: +2.55 % at h = 0.015 m); before them 4.9 %, and refining does not close the gap at the cost of a
// test (DISABLED_FloatingBoxResolution: 2.5 / 3.3 / 4 / 5 cells per draft give +4.9 / +17.2 /
// +7.5 / +3.2 %, and 6.7 cells (h = 0.0075 m, 256 s) +7.5 %; the error follows where the bottom
// rests between node planes). The coupling is
// not the cause: the box is in force balance, and a fixed box held at that depth gets the same
// upward force. The water's force on a downward-facing face (a lid) does not see where the face
// lies within a cell: the node contact knows only which nodes are inside it, and fixed 2-D lids
// 0.004 m apart at h = 0.02 m give the same force to all digits (docs/validation.md), so the
// box settles on a staircase and its draft scatters by up to ~0.6 h / d. Until that is fixed
// this test holds the coupling to what it does right (force balance, no penetration, no tilt)
// and the draft to the measured band, so that a regression or a fix both show. The +11 %
// reported before 2026-11-23 was mostly measurement: the draft was taken from the whole tank's
// mass with incompressible water (+2.1 points) and the particles under the box crowd (+4 to +5
// points; see FloatingBox).
TEST(RigidCouplingTest, LightBoxFloatsInForceBalanceWithTheKnownLidForceDeficit) {
  const Floating f = FloatingBox(Tank{});
  EXPECT_NEAR(f.force, f.weight, 0.03 * f.weight);  // at rest the water carries the box
  EXPECT_GT(f.draft, f.expected);                    // deeper than Archimedes (the known gap)
  EXPECT_LT(f.draft, 1.08 * f.expected);             // measured +4.9 %; +6.8 % with mirrored ghost nodes (2026-12-01);
                                                     // +4.32 % with the obstacles' gap test and interpolated faces (2026-12-02)
  EXPECT_GT(f.draft_tank, f.draft);                  // the crowding under the box
}

// Folded ghost nodes (`domain.ghost_nodes: fold_all`, docs/walls.md) at the tank's frictionless
// walls, in a slab three cells thick: the box floats 1.6 % deeper than its Archimedes draft
// instead of the mirror's 4.2 %, upright and in force balance. Measured 2026-12-07 by hand (draft below
// the open water, averaged over 1.5-2 s; mirror / fold_all): h = 0.02 m, slab 3 / 4 / 6 cells
// +4.18 / +4.87 / +4.18 % against +1.58 / +1.37 / +1.31 %; h = 0.015 m +2.55 against +0.32 %;
// h = 0.0125 m +9.3 against +7.4 % (both tilt by 0.045 rad: the staircase of
// LightBoxFloats... is still there); h = 0.01 m +4.08 against +1.65 %. So fold_all takes about
// 2.5 points off the draft error at every resolution, and within 3 % at three of the four.
// In the default slab of two cells the fold of both z walls lands on the middle node plane and
// the box tilts (+11.5 %, 0.022 rad), which made fold_all look worse before.
TEST(RigidCouplingTest, FoldedGhostNodesFloatTheBoxWithinThreePercentAtThisResolution) {
  Tank mirror, folded;
  mirror.slab_cells = folded.slab_cells = 3;
  folded.ghosts = "fold_all";
  const Floating m = FloatingBox(mirror);
  const Floating f = FloatingBox(folded);
  EXPECT_NEAR(f.force, f.weight, 0.03 * f.weight);
  EXPECT_NEAR(f.draft, f.expected, 0.03 * f.expected);
  EXPECT_LT(std::abs(f.draft - f.expected), 0.6 * std::abs(m.draft - m.expected));
}

// Node-based anti-locking (AS1, the Newtonian fluid's default) lets the water's particles crowd
// at the floor: each particle's J is replaced by its supports' mean, so a particle pressed closer
// to its neighbours than its J says meets no pressure. In this tank (slab three cells thick,
// mirrored ghosts) the particle volume J V0 in the bottom 0.04 m band reaches 1.4x its space by
// 2 s and 1.7x by 5 s, with or without the box, in 2-D and in a slab eight cells thick
// (by hand, 2026-12-08; docs/antilocking.md, "Crowding"); the floating box rides the crowding
// water down: its bottom sank 0.1198 -> 0.1151 -> 0.1092 -> 0.1066 m at 1 / 2 / 4 / 5 s (without
// anti-locking 0.1245 / 0.1230 / 0.1226 / 0.1222). Particle shifting (particle_shifting: true)
// moves crowded particles apart: the box then stops within 0.5 mm after 2 s and floats at its
// Archimedes draft below the visible surface. Below the open water's mass-based surface it reads
// deeper (+15 %): the shifted open water still holds about 4 % more particle volume than its
// space, most of it in the top band, so its mass stands for a surface higher than the one seen.
// KNOWN GAP: with shifting the box does not stay upright. The shift breaks the scene's mirror
// symmetry (round-off grows from 1e-15 m to 3e-8 m between 0.10 and 0.15 s, in the tank without
// the box as well), the drop then splashes unevenly, and the box tilts by 0.023 rad at 0.25 s
// and 0.082 rad at 0.5 s and rocks by up to 0.032 rad after 3 s. Without shifting it stays at 0
// to all digits only because the drop is exactly symmetric: offset by 1 mm, the box without
// anti-locking also tilts (0.050 rad at 0.25 s), but it settles (0.016 rad after 3 s, 0.001 at
// 5 s), while with shifting it keeps rocking (0.035 rad after 3 s). A particle ends up to 2e-4 h
// inside the box (docs/antilocking.md, "Crowding without damping, and a floating body").
TEST(RigidCouplingTest, NodeAntiLockingLetsTheFloatingBoxSinkUnlessTheParticlesShift) {
  Tank plain;
  plain.slab_cells = 3;
  plain.antilocking = "node";
  plain.end = 4.0;
  plain.average_from = 3.5;
  plain.creep_from = 2.0;
  Tank shifted = plain;
  shifted.shifting = true;
  shifted.max_tilt = 0.12;     // measured 0.082 rad (the known gap above)
  shifted.max_inside = 1e-3;   // measured 2.0e-4 h
  const Floating p = FloatingBox(plain);
  const Floating s = FloatingBox(shifted);
  EXPECT_LT(p.creep, -0.003);  // measured -4.5 mm from 2.0-2.5 s to 3.5-4 s; shifted -0.12 mm
  EXPECT_GT(p.draft_visible, 1.1 * p.expected);
  EXPECT_LT(std::abs(s.creep), 0.001);
  EXPECT_NEAR(s.draft_visible, s.expected, 0.03 * s.expected);
  EXPECT_NEAR(s.force, s.weight, 0.03 * s.weight);
}

// The draft error against resolution in the coarse tank (about 4 min single-threaded; run by
// hand with --gtest_also_run_disabled_tests --gtest_filter=*Resolution*). Measured 2026-11-23
// (draft below the open water, compressible Archimedes): see docs/validation.md.
// SURGE_FLOAT_RUNS="ghosts slab dx[,dx...] [faces]" (e.g. "fold_all 3 0.02,0.0125 nodes") runs
// those cells instead, with the default antilocking (none) and contact.faces (interpolated);
// SURGE_FLOAT_AL (the antilocking map's inside, e.g. "node, fit: linear"), SURGE_FLOAT_SHIFT
// (set: particle_shifting) and SURGE_FLOAT_END (run end; the average is over its last 0.5 s)
// change those runs.
TEST(RigidCouplingTest, DISABLED_FloatingBoxResolution) {
  if (const char* runs = std::getenv("SURGE_FLOAT_RUNS")) {
    std::istringstream in(runs);
    Tank t;
    std::string sizes;
    in >> t.ghosts >> t.slab_cells >> sizes;
    if (std::string faces; in >> faces) t.faces = faces;
    if (const char* al = std::getenv("SURGE_FLOAT_AL")) t.antilocking = al;
    if (std::getenv("SURGE_FLOAT_SHIFT")) t.shifting = true;
    if (const char* e = std::getenv("SURGE_FLOAT_END")) {
      t.end = std::stod(e);
      t.average_from = t.end - 0.5;
    }
    std::istringstream list(sizes);
    for (std::string dx; std::getline(list, dx, ',');) {
      t.dx = std::stod(dx);
      FloatingBox(t);
    }
    return;
  }
  for (const Real dx : {0.02, 0.015, 0.0125, 0.01}) {
    Tank t;
    t.dx = dx;
    FloatingBox(t);
  }
  Tank node;
  node.antilocking = "node";
  FloatingBox(node);
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

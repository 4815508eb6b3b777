// Rigid obstacles against closed forms (issue #5, shared/VALIDATION.md): hydrostatic thrust of
// water at rest on an obstacle box and on a domain wall (1/2 rho g h^2 per metre), a block on an
// incline of a frictional floor given as a domain wall and as a plane obstacle (a = g (sin th -
// mu cos th), sticking when tan th <= mu), and the impulse balance of an elastic disk bouncing
// off an obstacle (the logged force integrates to the disk's momentum change). In every case no
// particle may end inside an obstacle.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "contact/geometry.h"
#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

using testing::MaxPenetration;
using testing::TotalMass;

// --- Hydrostatic thrust ------------------------------------------------------------------------
// Water (reduced bulk modulus, node-based anti-locking: the fluid default) fills x in [0, 0.1]
// between the slip wall x- of the domain and an obstacle box on x >= 0.1; gravity ramped over
// 0.2 s (seed App. B.2.3). After settling, the time-averaged horizontal force on each side is
// compared with 1/2 rho g h^2 (per metre), h = m / (rho W) the incompressible depth.
constexpr const char* kTankScene = R"(name: tank_obstacle
dimension: 2
time: {end: 1.0, cfl: 0.3}
gravity: [0, -9.81]
gravity_ramp: 0.2
grid: {cell_size: 0.004, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0]
  max: [0.16, 0.12]
  walls: {x-: slip, x+: slip, y-: slip, y+: slip}
materials:
  water: {model: newtonian_fluid, density: 997.5, bulk_modulus: 2.0e6, viscosity: 0.001}
bodies:
  - name: water
    material: water
    region: {box: {min: [0, 0], max: [0.1, 0.06]}}
    particles_per_cell: 2
obstacles:
  - name: wall
    shape: {box: {min: [0.1, 0], max: [0.16, 0.12]}}
sensors:
  - {name: lower, box: {min: [0.099, 0], max: [0.16, 0.03]}}
  - {name: upper, box: {min: [0.099, 0.03], max: [0.16, 0.12]}}
)";

TEST(ObstacleTest, HydrostaticThrustOnObstacleBoxAndDomainWall) {
  constexpr Real kRho = 997.5, kG = 9.81, kW = 0.1, kAvgFrom = 0.7;
  LoadedScene scene = LoadSceneFromString(kTankScene, "tank_obstacle.yaml");
  const Real mass = TotalMass(scene.state.particles);
  const Real h = mass / (kRho * kW);
  Real box = 0, wall = 0, floor_obstacle = 0, lower = 0, upper = 0, sensor_gap = 0;
  int n = 0;
  testing::RunUntil(scene, 1.0, [&](const State& s, const StepReport& r) {
    if (s.time < kAvgFrom) return;
    box += r.obstacles.at(0).force.x();                  // pushed towards +x
    wall += -r.walls.force[int(Face::kXMin)].x();         // domain wall x-: pushed towards -x
    floor_obstacle += r.obstacles.at(0).force.y();
    lower += r.sensors.at(0).force.x();
    upper += r.sensors.at(1).force.x();
    // The two sensors cover every obstacle node once: their sum is the obstacle's force.
    sensor_gap = std::max(sensor_gap, std::abs(r.sensors.at(0).force.x() +
                                               r.sensors.at(1).force.x() -
                                               r.obstacles.at(0).force.x()));
    ++n;
  });
  box /= n;
  wall /= n;
  floor_obstacle /= n;
  lower /= n;
  upper /= n;
  // Force sensors: the hydrostatic load below and above y = 0.03 m, integral of rho g (h - y).
  const Real lower_expected = kRho * kG * (h * 0.03 - 0.5 * 0.03 * 0.03);
  const Real upper_expected = 0.5 * kRho * kG * h * h - lower_expected;
  std::printf("sensors: lower strip %.3f N/m (closed form %.3f, %+.2f %%), upper strip %.3f N/m "
              "(closed form %.3f, %+.2f %%)\n",
              lower, lower_expected, 100 * (lower / lower_expected - 1), upper, upper_expected,
              100 * (upper / upper_expected - 1));
  std::printf("sensors: largest |lower + upper - obstacle| over the averaging window %.3g N/m\n",
              sensor_gap);
  EXPECT_LT(sensor_gap, 1e-9 * box);
  EXPECT_NEAR(lower, lower_expected, 0.03 * lower_expected);
  // The upper strip carries the whole -1.8 % deficit of the total (-6 % of its own load): near the
  // free surface the stress of the top particle layer is spread over a cell by the B-splines.
  EXPECT_NEAR(upper, upper_expected, 0.08 * upper_expected);
  const Real expected = 0.5 * kRho * kG * h * h;  // per metre of thickness
  std::printf("hydrostatic thrust (h = %.4f m): obstacle box %.3f N/m, domain wall %.3f N/m, "
              "1/2 rho g h^2 = %.3f N/m (errors %+.2f %%, %+.2f %%); vertical force on the box "
              "%.3g N/m; deepest particle inside %.2e m\n",
              h, box, wall, expected, 100 * (box / expected - 1), 100 * (wall / expected - 1),
              floor_obstacle, MaxPenetration(scene));
  EXPECT_NEAR(box, expected, 0.02 * expected);
  EXPECT_NEAR(wall, expected, 0.02 * expected);
  EXPECT_LT(std::abs(floor_obstacle), 0.02 * expected);  // a smooth vertical face: no shear
  EXPECT_EQ(MaxPenetration(scene), 0);
}

// --- Block on an incline -----------------------------------------------------------------------
// Gravity rotated by th (seed eq. (7.20) does the same for slopes); the floor y = 0 is either the
// frictional domain wall y- or a plane obstacle with the same mu. The block's mean velocity along
// the slope is fitted by least squares over t in [0.1, 0.4] s, after gravity was ramped up over
// 0.05 s (seed App. B.2.3) and the contact has settled.
std::string InclineScene(Real theta_deg, Real mu, bool obstacle) {
  const Real th = theta_deg * std::numbers::pi / 180, g = 9.81;
  const std::string floor =
      obstacle ? "  walls: {x-: slip, x+: slip}\n"
                 "obstacles:\n"
                 "  - name: floor\n"
                 "    shape: {plane: {point: [0, 0], normal: [0, 1]}}\n"
                 "    contact: {friction: " + std::to_string(mu) + "}\n"
               : "  walls: {x-: slip, x+: slip, y-: {friction: " + std::to_string(mu) + "}}\n";
  // The obstacle lives below y = 0, inside the domain; the domain wall is the domain's edge.
  const std::string ymin = obstacle ? "-0.2" : "0";
  std::string text = "name: incline\ndimension: 2\ntime: {end: 0.4, cfl: 0.4}\ngravity_ramp: 0.05\n";
  text += "gravity: [" + std::to_string(g * std::sin(th)) + ", " + std::to_string(-g * std::cos(th)) + "]\n";
  text += "grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: musl}\n";
  text += "domain:\n  min: [0, " + ymin + "]\n  max: [4, 1]\n" + floor.substr(0, floor.find("obstacles:"));
  text += "materials:\n  rubber: {model: neo_hookean, density: 2000, youngs_modulus: 5.0e7, poisson_ratio: 0.3}\n";
  text += "bodies:\n  - name: block\n    material: rubber\n"
          "    region: {box: {min: [0.5, 0], max: [1.0, 0.25]}}\n    particles_per_cell: 2\n";
  if (obstacle) text += floor.substr(floor.find("obstacles:"));
  return text;
}

// Least-squares slope of the block's mean velocity along x over t in [t0, t1].
Real FittedAcceleration(const std::string& scene_text, Real* penetration) {
  LoadedScene scene = LoadSceneFromString(scene_text, "incline.yaml");
  std::vector<Real> t, v;
  testing::RunUntil(scene, 0.4, [&](const State& s, const StepReport&) {
    if (s.time < 0.1) return;
    Real m = 0, p = 0;
    for (size_t i = 0; i < s.particles.size(); ++i) {
      m += s.particles.mass[i];
      p += s.particles.mass[i] * s.particles.v[i].x();
    }
    t.push_back(s.time);
    v.push_back(p / m);
  });
  Real st = 0, sv = 0, stt = 0, stv = 0;
  const Real n = Real(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    st += t[i];
    sv += v[i];
    stt += t[i] * t[i];
    stv += t[i] * v[i];
  }
  *penetration = MaxPenetration(scene);
  return (n * stv - st * sv) / (n * stt - st * st);
}

TEST(ObstacleTest, BlockSlidesDownAFrictionalInclineAtTheCoulombRate) {
  constexpr Real kTheta = 30, kMu = 0.3, kG = 9.81;
  const Real th = kTheta * std::numbers::pi / 180;
  const Real expected = kG * (std::sin(th) - kMu * std::cos(th));
  for (bool obstacle : {false, true}) {
    Real penetration = 0;
    const Real a = FittedAcceleration(InclineScene(kTheta, kMu, obstacle), &penetration);
    std::printf("incline %g deg, mu %g, floor as %s: a = %.5f m/s^2, g (sin - mu cos) = %.5f "
                "(error %+.3f %%); deepest particle inside %.2e m\n",
                kTheta, kMu, obstacle ? "plane obstacle" : "domain wall", a, expected,
                100 * (a / expected - 1), penetration);
    EXPECT_NEAR(a, expected, 0.01 * expected);
    EXPECT_EQ(penetration, 0);
  }
}

TEST(ObstacleTest, BlockSticksWhenTanThetaIsBelowMu) {
  constexpr Real kTheta = 15, kMu = 0.3;  // tan 15 deg = 0.268 < 0.3
  for (bool obstacle : {false, true}) {
    Real penetration = 0;
    const Real a = FittedAcceleration(InclineScene(kTheta, kMu, obstacle), &penetration);
    std::printf("incline %g deg, mu %g, floor as %s: a = %.3e m/s^2 (sticks: 0)\n", kTheta, kMu,
                obstacle ? "plane obstacle" : "domain wall", a);
    EXPECT_LT(std::abs(a), 0.01 * 9.81 * std::sin(kTheta * std::numbers::pi / 180));
  }
}

// --- Impulse balance ---------------------------------------------------------------------------
// An elastic disk (no gravity) hits an obstacle box and bounces off. The logged force on the
// obstacle, summed as F dt over every step, equals the disk's momentum loss p(0) - p(end).
constexpr const char* kDiskScene = R"(name: disk_impact
dimension: 2
time: {end: 0.12, cfl: 0.3}
gravity: [0, 0]
grid: {cell_size: 0.01, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [0.6, 0.6]
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies:
  - name: disk
    material: rubber
    region: {sphere: {center: [0.3, 0.3], radius: 0.08}}
    particles_per_cell: 2
    velocity: [-1.0, -2.0]
obstacles:
  - name: block
    shape: {box: {min: [0.1, 0.05], max: [0.5, 0.2]}}
)";

TEST(ObstacleTest, LoggedImpulseEqualsTheMomentumTheDiskLoses) {
  LoadedScene scene = LoadSceneFromString(kDiskScene, "disk_impact.yaml");
  auto momentum = [](const Particles& P) {
    Vec3 p = Vec3::Zero();
    for (size_t i = 0; i < P.size(); ++i) p += P.mass[i] * P.v[i];
    return p;
  };
  const Vec3 p0 = momentum(scene.state.particles);
  Vec3 impulse = Vec3::Zero();
  Real peak = 0, penetration = 0;
  testing::RunUntil(scene, 0.12, [&](const State& s, const StepReport& r) {
    impulse += s.dt * r.obstacles.at(0).force;
    peak = std::max(peak, r.obstacles.at(0).force.norm());
    penetration = std::max(penetration, MaxPenetration(scene));
  });
  const Vec3 dp = p0 - momentum(scene.state.particles);
  std::printf("disk impact: momentum lost (%.5f, %.5f) N s, logged impulse (%.5f, %.5f) N s "
              "(error %.3f %% of |p0|); peak force %.1f N/m; final vy %.3f m/s; deepest "
              "particle inside %.2e m\n",
              dp.x(), dp.y(), impulse.x(), impulse.y(), 100 * (impulse - dp).norm() / p0.norm(),
              peak, momentum(scene.state.particles).y() / TotalMass(scene.state.particles),
              penetration);
  EXPECT_GT(-dp.y(), 0.5 * std::abs(p0.y()));      // it bounced: the y momentum reversed sign
  EXPECT_LT((impulse - dp).norm(), 0.01 * dp.norm());
  EXPECT_EQ(penetration, 0);
  EXPECT_LT(std::abs(impulse.x()), 0.05 * std::abs(impulse.y()));  // smooth top face
}

// --- Adhesion ----------------------------------------------------------------------------------
// An elastic block (0.2 m x 0.1 m, 1000 kg/m^3: weight 196 N/m) hangs under a plane ceiling. A
// separable contact releases it; an adhesion of 2000 Pa holds it (about 13 contact nodes x h =
// 0.26 m can carry 520 N/m); 300 Pa cannot (78 N/m).
Real HangingBlockDrop(Real adhesion) {
  const std::string text = R"(name: hanging_block
dimension: 2
time: {end: 0.3, cfl: 0.4}
gravity: [0, -9.81]
gravity_ramp: 0.05
grid: {cell_size: 0.02, shape_function: quadratic_bspline, transfer: apic, update: musl}
domain:
  min: [0, 0]
  max: [1, 0.6]
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 2.0e6, poisson_ratio: 0.3}
bodies:
  - name: block
    material: rubber
    region: {box: {min: [0.4, 0.4], max: [0.6, 0.5]}}
    particles_per_cell: 2
obstacles:
  - name: ceiling
    shape: {plane: {point: [0, 0.5], normal: [0, -1]}}
    contact: {adhesion: )" + std::to_string(adhesion) + "}\n";
  LoadedScene scene = LoadSceneFromString(text, "hanging_block.yaml");
  auto mean_y = [](const Particles& P) {
    Real y = 0;
    for (const Vec3& x : P.x) y += x.y();
    return y / Real(P.size());
  };
  const Real y0 = mean_y(scene.state.particles);
  testing::RunUntil(scene, 0.3, [](const State&, const StepReport&) {});
  return y0 - mean_y(scene.state.particles);
}

TEST(ObstacleTest, AdhesionHoldsAHangingBlockOnlyWhenStrongEnough) {
  const Real none = HangingBlockDrop(0), weak = HangingBlockDrop(300), strong = HangingBlockDrop(2000);
  std::printf("hanging block drop after 0.3 s: no adhesion %.4f m, 300 Pa %.4f m, 2000 Pa %.5f m "
              "(free fall from rest with the 0.05 s ramp: %.3f m)\n",
              none, weak, strong, 0.5 * 9.81 * 0.275 * 0.275);
  EXPECT_GT(none, 0.2);
  EXPECT_GT(weak, 0.1);
  EXPECT_LT(strong, 0.002);  // elastic sag only
}

// Hydrostatics of the 2-D water tanks below (rho0 = 1000 kg/m^3, K = 2e5 Pa, g = 9.81): the mass
// per m^2 above height y in a free column whose surface is s, with rho = rho0 exp(p / K) (first
// order in p / K < 1 %: K/g (exp(rho0 g (s - y) / K) - 1)), and the surface s at which a tank
// `tank` wide holds `mass` [kg/m] around fixed boxes {width, bottom, top} (bisection).
constexpr Real kTankRho = 1000, kTankG = 9.81, kTankK = 2.0e5;
Real MassAbove(Real y, Real s) {
  return kTankK / kTankG * (std::exp(kTankRho * kTankG * std::max(s - y, Real(0)) / kTankK) - 1);
}
Real SurfaceFromMass(Real mass, Real tank, const std::vector<std::array<Real, 3>>& boxes) {
  auto total = [&](Real s) {
    Real m = tank * MassAbove(0, s);
    for (const auto& b : boxes) m -= b[0] * (MassAbove(b[1], s) - MassAbove(b[2], s));
    return m;
  };
  Real lo = 0.1, hi = 0.3;
  for (int k = 0; k < 60; ++k) (total(0.5 * (lo + hi)) > mass ? hi : lo) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

// --- Lid buoyancy (force on downward- and upward-facing faces) ------------------------------------
// A 2-D tank 0.6 m wide, water ~0.2 m deep (K = 2e5 Pa, no anti-locking, h = 0.01 m, ppc 2), two
// fixed boxes 0.16 m wide with their horizontal faces half a cell off the grid planes: A pierces the
// surface (its bottom, a "lid", ~9.4 cells deep), B is submerged (lid ~15 cells deep, top face ~7).
// The time-averaged force on each horizontal face is compared with p(y) A, p the hydrostatic
// pressure of the water's own mass: m(y) = mass per metre^2 above y in a free column with
// rho = rho0 exp(p / K) (first order in p / K < 1 %: K/g (exp(rho0 g (s - y) / K) - 1)), the
// surface s found from the particle mass. Measured 2026-11-23: lid A -2.2 %, lid B -3.2 %, top of
// B -2.0 %; 2026-12-01 with mirrored ghost nodes at the walls (domain.ghost_nodes, now the
// default; docs/walls.md): -2.3 %, -4.2 %, -2.3 % (lid B's gate widened from 4 % to 4.5 % then).
// Before the face's nodal layer included the first node row behind an off-grid face at
// the box edges (contact.cpp), the lids lost one cell of their width: -5.7 % / -5.2 % (at h = 0.02:
// -16 % -> -8 %). Known, not fixed: the edge node of a lid carries ~0.36 of p h instead of 0.5
// and the interior nodes ~5 % low at 5 cells of depth, so at h = 0.02 the lids are still -7 to -8 %
// (aligned or not); submerged vertical faces are -5 % (aligned) to -13 % (off-grid) at h = 0.01.
constexpr const char* kLidScene = R"(name: lid_buoyancy
dimension: 2
time: {end: 1.6, cfl: 0.3}
gravity: [0, -9.81]
gravity_ramp: 0.1
grid: {cell_size: 0.01, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0]
  max: [0.6, 0.4]
  walls: {x-: slip, x+: slip, y-: slip, y+: slip}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e5, viscosity: 0.01,
          antilocking: {method: none}}
bodies:
  - {name: water, material: water, region: {box: {min: [0, 0], max: [0.6, 0.2]}}, particles_per_cell: 2}
obstacles:
  - {name: A, shape: {box: {min: [0.1, 0.105], max: [0.26, 0.35]}}, motion: fixed}
  - {name: B, shape: {box: {min: [0.34, 0.045], max: [0.5, 0.125]}}, motion: fixed}
)";

TEST(ObstacleTest, LidBuoyancyOnOffGridHorizontalFacesWithinThreePercent) {
  constexpr Real kW = 0.16, kTank = 0.6;
  constexpr Real kA = 0.105, kB0 = 0.045, kB1 = 0.125;  // lid A, lid B, top of B
  constexpr int kYMin = 2, kYMax = 3;                   // box faces x-, x+, y-, y+
  LoadedScene scene = LoadSceneFromString(kLidScene, "lid_buoyancy.yaml");
  const Real s = SurfaceFromMass(TotalMass(scene.state.particles), kTank,
                                 {{kW, kA, 1e9}, {kW, kB0, kB1}});  // A pierces the surface
  auto load = [&](Real y) { return kTankG * MassAbove(y, s) * kW; };  // p(y) x width [N/m]
  Real lid_a = 0, lid_b = 0, top_b = 0;
  int n = 0;
  testing::RunUntil(scene, 1.6, [&](const State& st, const StepReport& r) {
    if (st.time < 1.0) return;
    lid_a += r.obstacles.at(0).faces.at(kYMin).force.y();
    lid_b += r.obstacles.at(1).faces.at(kYMin).force.y();
    top_b += -r.obstacles.at(1).faces.at(kYMax).force.y();
    ++n;
  });
  lid_a /= n;
  lid_b /= n;
  top_b /= n;
  std::printf("lid buoyancy (h = 0.01 m, faces half a cell off the grid, surface %.4f m): lid A "
              "%.3f N/m (p A %.3f, %+.2f %%), lid B %.3f N/m (%.3f, %+.2f %%), top of B %.3f N/m "
              "(%.3f, %+.2f %%); deepest particle inside %.2e m\n",
              s, lid_a, load(kA), 100 * (lid_a / load(kA) - 1), lid_b, load(kB0),
              100 * (lid_b / load(kB0) - 1), top_b, load(kB1), 100 * (top_b / load(kB1) - 1),
              MaxPenetration(scene));
  EXPECT_NEAR(lid_a, load(kA), 0.03 * load(kA));
  EXPECT_NEAR(lid_b, load(kB0), 0.045 * load(kB0));
  EXPECT_NEAR(top_b, load(kB1), 0.03 * load(kB1));
  EXPECT_EQ(MaxPenetration(scene), 0);
}

// --- A lid anywhere within a cell --------------------------------------------------------------
// A 2-D tank 0.6 m wide, water 0.16 m deep (K = 2e5 Pa, no anti-locking, h = 0.01 m, ppc 2), one
// fixed box 0.2 m wide piercing the surface with its bottom (the lid) at y_b = 0.1003, 0.1050 or
// 0.1097 m, all between the node planes 0.10 and 0.11 m and above the same particle row. The
// time-averaged lid force over 1.0-1.6 s is compared with p(y_b) w, the hydrostatic pressure of
// the water's own mass as in the lid test above, for the interpolated face constraint
// (contact.faces: interpolated, the default; docs/obstacle-faces.md) and for the node-by-node
// contact (faces: nodes). The interpolated constraint is the more accurate at every position; it
// does not remove the dependence on where the particles sit (docs/obstacle-faces.md, "Limits").
struct LidRun {
  Real force = 0, expected = 0;  // [N/m]
};

LidRun RunLidAt(Real bottom, const std::string& faces, Real dx = 0.01) {
  constexpr Real kW = 0.2, kTank = 0.6;
  const std::string b = std::to_string(bottom);
  const std::string text = R"(name: lid_position
dimension: 2
time: {end: 1.6, cfl: 0.3}
gravity: [0, -9.81]
gravity_ramp: 0.1
grid: {cell_size: )" + std::to_string(dx) + R"(, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0]
  max: [0.6, 0.4]
  walls: {x-: slip, x+: slip, y-: slip, y+: slip}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e5, viscosity: 0.01,
          antilocking: {method: none}}
bodies:
  - {name: water, material: water, region: {box: {min: [0, 0], max: [0.6, 0.16]}}, particles_per_cell: 2}
obstacles:
  - {name: lid, shape: {box: {min: [0.2, )" + b + R"(], max: [0.4, 0.38]}}, motion: fixed,
     contact: {faces: )" + faces + R"(}}
)";
  LoadedScene scene = LoadSceneFromString(text, "lid_position.yaml");
  const Real s = SurfaceFromMass(TotalMass(scene.state.particles), kTank, {{kW, bottom, 1e9}});
  LidRun out;
  out.expected = kTankG * MassAbove(bottom, s) * kW;
  int n = 0;
  testing::RunUntil(scene, 1.6, [&](const State& st, const StepReport& r) {
    if (st.time < 1.0) return;
    out.force += r.obstacles.at(0).faces.at(2).force.y();  // face y-
    ++n;
  });
  out.force /= n;
  EXPECT_EQ(MaxPenetration(scene), 0) << faces << " " << bottom;
  return out;
}

TEST(ObstacleTest, LidAnywhereInACellIsCloserToPAWithInterpolatedFaces) {
  for (const Real bottom : {0.1003, 0.1050, 0.1097}) {
    const LidRun a = RunLidAt(bottom, "interpolated");
    const LidRun b = RunLidAt(bottom, "nodes");
    const Real ea = a.force / a.expected - 1, eb = b.force / b.expected - 1;
    std::printf("lid at y = %.4f m (h = 0.01 m): p A %.4f N/m; interpolated faces %.4f (%+.2f %%), "
                "nodes %.4f (%+.2f %%)\n", bottom, a.expected, a.force, 100 * ea, b.force, 100 * eb);
    EXPECT_LT(std::abs(ea), 0.03) << bottom;
    EXPECT_LT(std::abs(ea), std::abs(eb)) << bottom;
  }
}

// --- The contact acts when the material arrives -------------------------------------------------
// The seed's column impact as shipped (scenes/column_impact_3d.yaml, h = 0.5 m, 2 particles per
// cell: half-size r = 0.125 m; dt <= 2e-3 s as in the CI sweep) up to t = 0.7 s: the surge front
// (largest particle x) at the first step the column's impact face x- (at x = 9 m) carries more than
// 1 kN. With the obstacles' gap test (contact.gap_test, the default; docs/obstacle-faces.md) the
// front is then within the touch distance 1.5 r of the face (allowing one step of travel, < 0.05
// m); with the old node-by-node contact the column felt the surge while the front was still about
// 1.5 h = 0.75 m away. Measured 2026-12-02: default, first force at t = 0.498 s with the front at
// 8.813 m (0.187 m short of the face); old contact, t = 0.268 s, front 8.277 m (0.72 m short).
struct FirstContact {
  Real time = -1, front = 0;  // [s], [m]
};

FirstContact FirstColumnForce(const std::vector<std::string>& overrides) {
  std::vector<std::string> o = {"time.max_dt=2e-3", "time.end=0.7"};
  o.insert(o.end(), overrides.begin(), overrides.end());
  LoadedScene scene = LoadScene(testing::ScenePath("column_impact_3d.yaml"), o);
  FirstContact first;
  testing::RunUntil(scene, 0.7, [&](const State& s, const StepReport& r) {
    if (first.time >= 0 || std::abs(r.obstacles.at(0).faces.at(0).force.x()) <= 1e3) return;
    first.time = s.time;
    for (const Vec3& x : s.particles.x) first.front = std::max(first.front, x.x());
  });
  return first;
}

TEST(ObstacleTest, ColumnFeelsTheSurgeOnlyWhenItArrives) {
  constexpr Real kFace = 9.0, kTouch = 1.5 * 0.125;
  const FirstContact now = FirstColumnForce({});
  const FirstContact old =
      FirstColumnForce({"obstacles.0.contact.faces=nodes", "obstacles.0.contact.gap_test=false"});
  std::printf("column impact, first force > 1 kN on face x-: default t = %.3f s, front %.4f m; "
              "old contact t = %.3f s, front %.4f m (face at %.1f m)\n",
              now.time, now.front, old.time, old.front, kFace);
  ASSERT_GT(now.time, 0) << "the surge must reach the column by 0.7 s";
  EXPECT_GT(now.front, kFace - kTouch - 0.05);
  EXPECT_LT(old.front, kFace - 0.5);  // the defect: the old contact acts a cell and more early
}

// The last steps of a run land on the end time without a sliver step (NextTimeStep): in the dam
// break with barrier as shipped (scenes/dam_break_barrier_2d.yaml, end 2 s, plain MPM) no step
// of the last 20 is shorter than 0.85 of the one before, and the barrier force changes by less
// than 3 % from one step to the next there (the water piles against the barrier; the largest
// change was about 0.01 % a step with the node-by-node contact, 1.18 % since the obstacles' gap
// test and interpolated faces, 2026-12-02, docs/obstacle-faces.md). Before, the run ended with a step 1/48 of the others and the last force
// jumped by +50 % (25.4 against 16.9 kN/m), which `surge forces` then reported as the peak.
TEST(ObstacleTest, LastStepsLandOnTheEndTimeWithoutAForceSpike) {
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_barrier_2d.yaml"),
                                {"materials.water.antilocking={method: none}"});
  std::vector<Real> dt, force;
  const Real t_end = scene.model.time.end;
  testing::RunUntil(scene, t_end, [&](const State& s, const StepReport& r) {
    dt.push_back(s.dt);
    force.push_back(r.obstacles.at(0).force.x());
  });
  EXPECT_NEAR(scene.state.time, t_end, 1e-12 * t_end);
  ASSERT_GT(force.size(), 21u);
  Real worst_jump = 0, shortest = 1e300;
  for (size_t i = force.size() - 20; i < force.size(); ++i) {
    worst_jump = std::max(worst_jump, std::abs(force[i] - force[i - 1]) / std::abs(force[i - 1]));
    shortest = std::min(shortest, dt[i] / dt[i - 1]);
  }
  std::printf("last 20 steps to %.3g s: largest step-to-step barrier force change %.4f %%, "
              "shortest dt ratio %.4f, last dt %.4g s, last force %.1f N/m\n",
              t_end, 100 * worst_jump, shortest, dt.back(), force.back());
  EXPECT_GT(force.back(), 1000.0) << "the water must be on the barrier";
  EXPECT_LT(worst_jump, 0.03);
  EXPECT_GT(shortest, 0.85);
}

}  // namespace
}  // namespace surge

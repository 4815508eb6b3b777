// The stability suite (issue 8 item 2; docs/stability.md). Every scene of scenes/stress/ runs to
// its end with the default time settings (automatic dt, Courant number 0.4) and must show, at
// every step: no NaN/Inf and no J <= 0 (the health check), and where it applies no particle in
// or behind the obstacle, and a total mechanical energy E = kinetic + strain + gravitational that
// never grows by more than 1 % of its initial value (gravity measured from the domain's lowest
// corner) in the scenes where nothing does external work (fixed walls and obstacles only, no
// particles leaving). Cases made to fail must stop with exit code 3, a message naming the step,
// stage, field, particle, material and likely cause, a diagnostic checkpoint, and results that
// hold no snapshot of the failed state; a silent blow-up (energy growth without NaN) must be
// stopped by the energy guard.
//
// Each case prints one line (the table of docs/stability.md): particles, steps, dt against the
// CFL limit h / max(c + |v|) (spec §1.7) taken from the state at the start of each step, the
// smallest J, the energy growth and the wall time. Each test runs on one thread, so that ctest
// can run two at a time on two cores.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "app/run.h"
#include "io/checkpoint.h"
#include "step/stages.h"
#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

std::string StressScene(const std::string& name) {
  return std::string(SURGE_SOURCE_DIR) + "/scenes/stress/" + name + ".yaml";
}

struct CaseOptions {
  bool energy = true;  // false where work is done on the system or mass leaves it
  // Particles must stay in front of the plane through front_point with the normal front_normal
  // (pointing into the obstacle hit): front_normal . (x - front_point) <= 0. Zero normal: none.
  Vec3 front_point = Vec3::Zero();
  Vec3 front_normal = Vec3::Zero();
  // The front face x = x0 of an obstacle hit from x-.
  static CaseOptions FrontAtX(Real x0) {
    CaseOptions o;
    o.front_point = Vec3(x0, 0, 0);
    o.front_normal = Vec3::UnitX();
    return o;
  }
};

struct CaseResult {
  Health health;
  int64_t steps = 0;
  size_t particles = 0;
  int64_t removed = 0;
  Real dt_min = std::numeric_limits<Real>::infinity(), dt_max = 0;
  Real limit_at_dt_min = 0;  // the CFL limit h / max(c + |v|) of the step with the smallest dt
  Real courant_max = 0;      // largest dt / (h / max(c + |v|)) over the steps
  Real min_j = std::numeric_limits<Real>::infinity();
  Real energy_growth = 0;    // max_t (E(t) - E(0)) / E(0), E from the domain's lowest corner
  Real energy_end = 0;       // (E(end) - E(0)) / E(0): the dissipated share when negative
  // The same for the energy balance B = kinetic + gravitational + internal work - wall work +
  // the initial strain energy (B(0) = E(0)): the internal work counts what plasticity and
  // viscosity dissipate, so B falls only by the transfers' and contacts' numerical dissipation.
  Real balance_growth = 0;
  Real balance_end = 0;
  Real max_penetration = 0;  // deepest particle inside an obstacle [m]
  Real impulse_x = 0;        // time integral of the x force on the first obstacle [N s]
  Real max_behind = -std::numeric_limits<Real>::infinity();  // max n.(x - x0) past the front [m]
  double wall_seconds = 0;
};

// Gravitational energy of all particles at the domain's lowest corner: E is measured from there,
// so that E(0) is the energy the run could at most release.
Real FloorPotential(const Model& m, const Particles& P) {
  Real lowest = std::numeric_limits<Real>::infinity();
  for (int c = 0; c < (m.dim == 3 ? 8 : 4); ++c) {
    const Vec3 corner((c & 1) ? m.domain_max.x() : m.domain_min.x(),
                      (c & 2) ? m.domain_max.y() : m.domain_min.y(),
                      (c & 4) ? m.domain_max.z() : m.domain_min.z());
    lowest = std::min(lowest, -m.gravity.dot(corner));  // potential per kg, -g.x
  }
  Real mass = 0;
  for (Real mp : P.mass) mass += mp;
  return mass * lowest;
}

Real Mechanical(const EnergyRecord& e) { return e.kinetic + e.strain + e.gravitational; }

CaseResult RunCase(const std::string& name, const CaseOptions& opt,
                   const std::vector<std::string>& overrides = {}) {
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const auto t0 = std::chrono::steady_clock::now();
  LoadedScene scene = LoadScene(StressScene(name), overrides);
  const Model& m = scene.model;
  State& s = scene.state;
  CaseResult r;
  r.particles = s.particles.size();
  const Pipeline pipeline = MakePipeline(m);
  Workspace work;
  StepReport report;
  const Real floor = FloorPotential(m, s.particles);
  const EnergyRecord start = ComputeEnergy(m, s);
  const Real e0 = Mechanical(start) - floor;
  Real e_max = e0, e_end = e0;
  const auto balance = [&](const EnergyRecord& e) {
    return e.kinetic + e.gravitational + e.internal_work - e.wall_work + start.strain - floor;
  };
  Real b_max = e0, b_end = e0;
  std::vector<Real> c(m.materials.size());
  for (size_t k = 0; k < c.size(); ++k) c[k] = WaveSpeed(m.materials[k]);
  while (s.time < m.time.end * (1 - 1e-12)) {
    // The CFL limit at the start of the step (the state NextTimeStep reads).
    Real speed = 0;
    for (size_t p = 0; p < s.particles.size(); ++p)
      speed = std::max(speed, c[size_t(s.particles.material[p])] + s.particles.v[p].norm());
    const Real limit = m.dx / speed;
    Step(m, pipeline, s, work, report);
    if (report.health.status != HealthStatus::kOk) {
      r.health = report.health;
      break;
    }
    ++r.steps;
    // The last step is cut to land on time.end: left out of the dt range.
    if (s.time < m.time.end * (1 - 1e-12)) {
      if (s.dt < r.dt_min) r.dt_min = s.dt, r.limit_at_dt_min = limit;
      r.dt_max = std::max(r.dt_max, s.dt);
      r.courant_max = std::max(r.courant_max, s.dt / limit);
    }
    for (const Mat3& F : s.particles.F) r.min_j = std::min(r.min_j, F.determinant());
    if (opt.energy) {
      const EnergyRecord e = ComputeEnergy(m, s);
      e_end = Mechanical(e) - floor;
      e_max = std::max(e_max, e_end);
      b_end = balance(e);
      b_max = std::max(b_max, b_end);
    }
    if (!m.obstacles.empty()) {
      r.max_penetration = std::max(r.max_penetration, testing::MaxPenetration(scene));
      r.impulse_x += report.obstacles[0].force.x() * s.dt;
    }
    if (opt.front_normal != Vec3::Zero()) {
      for (const Vec3& x : s.particles.x)
        r.max_behind = std::max(r.max_behind, opt.front_normal.dot(x - opt.front_point));
    }
  }
  r.removed = s.particles_removed;
  r.energy_growth = (e_max - e0) / e0;
  r.energy_end = (e_end - e0) / e0;
  r.balance_growth = (b_max - e0) / e0;
  r.balance_end = (b_end - e0) / e0;
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  char energy[128] = "n/a";
  if (opt.energy)
    std::snprintf(energy, sizeof energy, "max %+.3g %%, end %+.3g %%; balance max %+.3g %%, end %+.3g %%",
                  100 * r.energy_growth, 100 * r.energy_end, 100 * r.balance_growth,
                  100 * r.balance_end);
  std::printf("[stability] %-26s %6zu particles %7lld steps  dt %.3g..%.3g s  CFL limit %.3g s  "
              "dt/limit <= %.3f  min J %.4f  energy %s  removed %lld  wall %.1f s\n",
              name.c_str(), r.particles, static_cast<long long>(r.steps), r.dt_min, r.dt_max,
              r.limit_at_dt_min, r.courant_max, r.min_j, energy,
              static_cast<long long>(r.removed), r.wall_seconds);
  return r;
}

// The checks every healthy case shares. The automatic dt is C = 0.4 of the CFL limit, or less
// where a viscous bound governs: never more.
void ExpectStable(const CaseResult& r, const CaseOptions& opt) {
  EXPECT_EQ(r.health.status, HealthStatus::kOk) << r.health.detail;
  EXPECT_GT(r.steps, 0);
  EXPECT_LE(r.courant_max, 0.4 * (1 + 1e-9));
  EXPECT_GT(r.min_j, 0.0);
  if (opt.energy) {
    EXPECT_LE(r.energy_growth, 0.01);
    EXPECT_LE(r.balance_growth, 0.01);
  }
  EXPECT_LE(r.max_penetration, 1e-9);
  if (opt.front_normal != Vec3::Zero()) {
    EXPECT_LE(r.max_behind, 1e-9);
  }
}

TEST(StabilityTest, SteelBarImpact) {
  const CaseOptions opt;
  ExpectStable(RunCase("steel_bar_impact_2d", opt), opt);
}

TEST(StabilityTest, WaterWithRealBulkModulus) {
  const CaseOptions opt;
  ExpectStable(RunCase("water_real_bulk_2d", opt), opt);
}

TEST(StabilityTest, NearlyIncompressibleBlock) {
  const CaseOptions opt;
  ExpectStable(RunCase("nearly_incompressible_2d", opt), opt);
}

TEST(StabilityTest, TaylorBarJ2) {
  const CaseOptions opt;
  ExpectStable(RunCase("taylor_bar_j2_3d", opt), opt);
}

TEST(StabilityTest, TaylorBarCopper190) {
  const CaseOptions opt;
  ExpectStable(RunCase("taylor_bar_copper_190_3d", opt), opt);
}

TEST(StabilityTest, DebrisOnWallAt50) {
  const CaseOptions opt = CaseOptions::FrontAtX(0.75);  // the wall's front face
  ExpectStable(RunCase("debris_wall_50ms_2d", opt), opt);
}

TEST(StabilityTest, FineCells) {
  const CaseOptions opt;
  ExpectStable(RunCase("fine_cells_2d", opt), opt);
}

TEST(StabilityTest, CoarseCells) {
  const CaseOptions opt;
  ExpectStable(RunCase("coarse_cells_2d", opt), opt);
}

// Mass leaves through the open sides: no energy balance. Every particle must leave (removed and
// counted) and the ones still in must stay healthy.
TEST(StabilityTest, ParticlesFlyingOut) {
  CaseOptions opt;
  opt.energy = false;
  const CaseResult r = RunCase("fly_out_2d", opt);
  ExpectStable(r, opt);
  EXPECT_EQ(r.removed, int64_t(r.particles));
}

TEST(StabilityTest, IsolatedParticlesAndTinyMassNodes) {
  const CaseOptions opt;
  ExpectStable(RunCase("isolated_particles_2d", opt), opt);
}

TEST(StabilityTest, StiffBodyOnSoftSoil) {
  const CaseOptions opt;
  ExpectStable(RunCase("stiff_on_soft_2d", opt), opt);
}

TEST(StabilityTest, ThinObstacleHitAtSpeed) {
  // the plate's front face; the plate is 4 mm (0.2 h) thick
  const CaseOptions opt = CaseOptions::FrontAtX(0.5);
  ExpectStable(RunCase("thin_obstacle_2d", opt), opt);
}

// A thin FCL mesh plate (assets/thin_plate.obj, 1 cm = 0.2 h) across a 3-D channel.
TEST(StabilityTest, ThinMeshPlateHitAtSpeed) {
  const CaseOptions opt = CaseOptions::FrontAtX(0.495);  // the mesh plate's front face
  ExpectStable(RunCase("thin_mesh_plate_3d", opt), opt);
}

// A thin polygon plate leaning 30 degrees from the vertical: its faces cut the grid lines.
TEST(StabilityTest, ThinTiltedPlateHitAtSpeed) {
  CaseOptions opt;
  // The front face, from the scene's polygon points 0 and 3 (30 degrees from the vertical,
  // through (0.5, 0) up to the 6 digits of the scene file); the normal points into the plate.
  const Vec3 a(0.471132, -0.05, 0), b(0.759808, 0.45, 0);
  opt.front_point = a;
  opt.front_normal = Vec3(b.y() - a.y(), a.x() - b.x(), 0).normalized();
  EXPECT_NEAR(opt.front_normal.x(), std::cos(std::numbers::pi / 6), 1e-6);
  ExpectStable(RunCase("thin_tilted_plate_2d", opt), opt);
}

// A round pillar 0.6 h across: the debris splits around it, none may end inside it.
TEST(StabilityTest, ThinPillarHitAtSpeed) {
  const CaseOptions opt;
  const CaseResult r = RunCase("thin_pillar_2d", opt);
  ExpectStable(r, opt);
  // The pillar must feel the debris that splits around it: at least a tenth of the stagnation
  // impulse rho v^2 D T over its own width D = 12 mm while the 0.26 m block passes
  // (T = 0.26 / 30 s), per metre. Measured 75 N s/m, 0.40 of it.
  const Real stagnation = 2000 * 30.0 * 30.0 * 0.012 * (0.26 / 30);
  std::printf("[stability] thin pillar: impulse %.3g N s/m, stagnation estimate %.3g N s/m\n",
              r.impulse_x, stagnation);
  EXPECT_GT(r.impulse_x, 0.1 * stagnation);
}

// --- Health stops -------------------------------------------------------------------------------

struct StopResult {
  RunSummary summary;
  std::string out;
};

StopResult RunToStop(const std::string& name, const std::vector<std::string>& overrides) {
  StopResult r;
  r.out = (std::filesystem::temp_directory_path() /
           ("surge_stability_" + name + "_" + std::to_string(::getpid())))
              .string();
  std::filesystem::remove_all(r.out);
  LoadedScene scene = LoadScene(StressScene(name), overrides);
  RunOptions options;
  options.out_dir = r.out;
  options.threads = 1;
  options.progress = ProgressMode::kQuiet;
  options.force = true;
  r.summary = RunScene(scene, options);
  return r;
}

std::vector<std::string> Files(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// Linear shape functions with APIC (docs/stability.md, "Linear shape functions with APIC"): the
// elastic block of scenes/studies/sliding_block_2d.yaml lifted off the floor, gravity off, with
// update: musl at the default Courant number 0.4. With C_p = sum v_{i,n+1} (grad N_ip)^T the
// block translating freely at 2 m/s grew its round-off stress to an energy-guard stop at 32 ms
// (2 particles per cell; 55 and 46 ms with 3 and 4; 4-7 ms with the perturbation below), and
// spinning at 10 rad/s it stopped after 6 ms. Now, translating to 0.1 s (928 steps), the stress
// must stay at round-off, and with a 1 mm/s velocity perturbation (elastic waves of about
// rho c dv = 0.4 kPa) of that size; spinning, it must keep its angular momentum and kinetic
// energy (APIC's point) for 0.2 s.
struct FreeBlock {
  Health health;
  Real max_stress = 0;      // largest |sigma_ij| over particles and steps [Pa]
  Real angular_ratio = 0;   // angular momentum about the centre at the end / at the start
  Real kinetic_ratio = 0;   // kinetic energy at the end / at the start
};

FreeBlock RunFreeLinearApicBlock(int ppc, Real perturbation, Real spin, Real end) {
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  LoadedScene scene = LoadScene(
      std::string(SURGE_SOURCE_DIR) + "/scenes/studies/sliding_block_2d.yaml",
      {"gravity=[0, 0]", "bodies.0.region.box.min=[1.5, 0.3]",
       "bodies.0.region.box.max=[2.0, 0.55]", "bodies.0.particles_per_cell=" + std::to_string(ppc),
       std::string("bodies.0.velocity=") + (spin > 0 ? "[0, 0]" : "[2, 0]"),
       "grid.shape_function=linear", "grid.transfer=apic", "grid.update=musl", "time.cfl=0.4",
       "time.end=" + std::to_string(end)});
  State& s = scene.state;
  Particles& P = s.particles;
  const Vec3 centre(1.75, 0.425, 0);
  for (size_t p = 0; p < P.size(); ++p) {  // deterministic noise; a rigid spin with its C_p
    const Vec3 r = P.x[p] - centre;
    P.v[p] += perturbation * Vec3(std::sin(1.7 * Real(p)), std::cos(2.3 * Real(p)), 0) +
              spin * Vec3(-r.y(), r.x(), 0);
    P.C[p].setZero();
    P.C[p](0, 1) = -spin;
    P.C[p](1, 0) = spin;
  }
  const auto momentum = [&](Real& angular, Real& kinetic) {
    angular = kinetic = 0;
    for (size_t p = 0; p < P.size(); ++p) {
      const Vec3 r = P.x[p] - centre;
      angular += P.mass[p] * (r.x() * P.v[p].y() - r.y() * P.v[p].x());
      kinetic += 0.5 * P.mass[p] * P.v[p].squaredNorm();
    }
  };
  Real angular0, kinetic0;
  momentum(angular0, kinetic0);
  const Pipeline pipeline = MakePipeline(scene.model);
  Workspace work;
  StepReport report;
  FreeBlock r;
  while (s.time < end * (1 - 1e-12)) {
    Step(scene.model, pipeline, s, work, report);
    if (report.health.status != HealthStatus::kOk) {
      r.health = report.health;
      break;
    }
    for (const Mat3 sigma : P.stress)
      r.max_stress = std::max(r.max_stress, sigma.cwiseAbs().maxCoeff());
  }
  Real angular1, kinetic1;
  momentum(angular1, kinetic1);
  r.angular_ratio = angular1 / angular0;
  r.kinetic_ratio = kinetic1 / kinetic0;
  std::printf("[stability] linear apic musl, %d ppc, dv %.0e m/s, spin %g rad/s: t %.3f s, "
              "max |sigma| %.3g Pa, K/K0 %.5f", ppc, perturbation, spin, s.time, r.max_stress,
              r.kinetic_ratio);
  if (spin > 0) std::printf(", L/L0 %.5f", r.angular_ratio);  // about the spin centre
  std::printf("\n");
  return r;
}

TEST(StabilityTest, LinearApicMuslTranslatingBlock) {
  for (int ppc : {2, 3, 4}) {
    const FreeBlock still = RunFreeLinearApicBlock(ppc, 0.0, 0.0, 0.1);
    EXPECT_EQ(still.health.status, HealthStatus::kOk) << ppc << " ppc: " << still.health.detail;
    EXPECT_LT(still.max_stress, 1e-5) << ppc << " ppc";
    const FreeBlock shaken = RunFreeLinearApicBlock(ppc, 1e-3, 0.0, 0.1);
    EXPECT_EQ(shaken.health.status, HealthStatus::kOk) << ppc << " ppc: " << shaken.health.detail;
    EXPECT_LT(shaken.max_stress, 5e3) << ppc << " ppc";
  }
}

TEST(StabilityTest, LinearApicMuslSpinningBlock) {
  const FreeBlock r = RunFreeLinearApicBlock(2, 0.0, 10.0, 0.2);  // rim speed 2.8 m/s
  EXPECT_EQ(r.health.status, HealthStatus::kOk) << r.health.detail;
  EXPECT_NEAR(r.angular_ratio, 1.0, 1e-3);
  EXPECT_NEAR(r.kinetic_ratio, 1.0, 1e-2);
}

// A fixed dt 2.3 times the CFL limit of steel: the run must stop within a few steps, name the
// step, the stage and field, the particle, the material and the cause (fixed_dt above the CFL
// limit, with the limit), write the diagnostic checkpoint of the failed step, keep the failed
// state out of the results, and refuse to continue from that checkpoint.
TEST(StabilityTest, FixedDtAboveCflStopsWithDiagnostic) {
  const StopResult r = RunToStop("steel_bar_impact_2d", {"time.fixed_dt=2e-6"});
  const std::string& msg = r.summary.exit_status;
  std::printf("[stability] fixed_dt stop: %s\n", msg.c_str());
  EXPECT_EQ(r.summary.exit_code, kExitUnhealthy);
  EXPECT_NE(msg.find("step "), std::string::npos) << msg;
  EXPECT_NE(msg.find("stage "), std::string::npos) << msg;
  EXPECT_NE(msg.find("field "), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle id "), std::string::npos) << msg;
  EXPECT_NE(msg.find("material 'steel'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Likely cause: time.fixed_dt is above the CFL limit"), std::string::npos) << msg;
  EXPECT_NE(msg.find("c = 5856 m/s"), std::string::npos) << msg;
  EXPECT_LT(r.summary.steps, 50);
  const std::vector<std::string> files = Files(r.out + "/checkpoints");
  ASSERT_EQ(files.size(), 1u);
  EXPECT_NE(files[0].find("steel_bar_impact_2d_failed_step_"), std::string::npos);
  const Checkpoint c = ReadCheckpoint(files[0]);
  EXPECT_EQ(c.state.step, r.summary.steps);
  // Only the t = 0 snapshot: the failed state is in the checkpoint, not in the results.
  EXPECT_EQ(r.summary.snapshots, 1);
  // The diagnostic checkpoint cannot be continued.
  LoadedScene again = LoadScene(StressScene("steel_bar_impact_2d"), {"time.fixed_dt=2e-6"});
  RunOptions options;
  options.out_dir = r.out;
  options.progress = ProgressMode::kQuiet;
  options.restart = files[0];
  EXPECT_THROW(RunScene(again, options), RunRefused);
  std::filesystem::remove_all(r.out);
}

// Without the energy series (output.energy: false) there is no energy guard: the same run stops
// two steps later at the health check, at an inverted particle made by grid_to_particle.
TEST(StabilityTest, FixedDtAboveCflWithoutEnergyStopsAtInvertedParticle) {
  const StopResult r = RunToStop("steel_bar_impact_2d", {"time.fixed_dt=2e-6", "output.energy=false"});
  const std::string& msg = r.summary.exit_status;
  std::printf("[stability] fixed_dt stop without energy: %s\n", msg.c_str());
  EXPECT_EQ(r.summary.exit_code, kExitUnhealthy);
  EXPECT_NE(msg.find("stage grid_to_particle, field J: inverted particle"), std::string::npos) << msg;
  EXPECT_NE(msg.find("material 'steel', body 'bar'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Likely cause: time.fixed_dt is above the CFL limit"), std::string::npos) << msg;
  EXPECT_EQ(Files(r.out + "/checkpoints").size(), 1u);
  std::filesystem::remove_all(r.out);
}

// The nu = 0.4999 block at time.cfl = 0.8 (twice the default) blows up without a NaN or an
// inverted particle for thousands of steps (measured without the guard: energy x430, exit code 0):
// the energy guard must stop it, naming the stage, the fastest particle and the cause.
TEST(StabilityTest, SilentBlowUpStoppedByEnergyGuard) {
  const StopResult r = RunToStop("nearly_incompressible_2d", {"time.cfl=0.8"});
  const std::string& msg = r.summary.exit_status;
  std::printf("[stability] energy guard stop: %s\n", msg.c_str());
  EXPECT_EQ(r.summary.exit_code, kExitUnhealthy);
  EXPECT_NE(msg.find("stage energy, field E"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle id "), std::string::npos) << msg;
  EXPECT_NE(msg.find("material 'rubber'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Likely cause: an instability below the wave-speed limit"), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("Lower time.cfl"), std::string::npos) << msg;
  EXPECT_LT(r.summary.steps, 1000);
  const std::vector<std::string> files = Files(r.out + "/checkpoints");
  ASSERT_EQ(files.size(), 1u);
  EXPECT_NE(files[0].find("nearly_incompressible_2d_failed_step_"), std::string::npos);
  std::filesystem::remove_all(r.out);
}

// on_exit: stop: the first particle through an open side stops the run with the particle, the
// stage domain_exit and the remedy named, and a diagnostic checkpoint.
TEST(StabilityTest, LeavingTheDomainWithOnExitStop) {
  const StopResult r = RunToStop("fly_out_2d", {"domain.on_exit=stop"});
  const std::string& msg = r.summary.exit_status;
  std::printf("[stability] on_exit stop: %s\n", msg.c_str());
  EXPECT_EQ(r.summary.exit_code, kExitUnhealthy);
  EXPECT_NE(msg.find("stage domain_exit, field x"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle id "), std::string::npos) << msg;
  EXPECT_NE(msg.find("material 'rubber'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("Likely cause"), std::string::npos) << msg;
  const std::vector<std::string> files = Files(r.out + "/checkpoints");
  ASSERT_EQ(files.size(), 1u);
  EXPECT_NE(files[0].find("fly_out_2d_failed_step_"), std::string::npos);
  std::filesystem::remove_all(r.out);
}

}  // namespace
}  // namespace surge

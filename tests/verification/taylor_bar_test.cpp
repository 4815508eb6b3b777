// J2 Taylor bar impact (Mast 2013 §7.1, Table 7.1; spec seed-validation-cases.md §4.1, case E1)
// and the copper Taylor-bar benchmark (Kamoulakos 1990; docs/taylor_bar.md). Both bars are
// quarter models hitting a frictionless slip wall at z = 0.
//  - H(t): the upper edge, the mean z of the particles that started in the top layer plus half a
//    particle spacing (the rear stays nearly undeformed).
//  - R(t): the mass centroid x̄, ȳ of the particles in contact with the wall (within one particle
//    spacing of it), with x̄ = ȳ = 4R/(3π) for a quarter disk (seed eqs. 7.3-7.4).
// The CI variants are coarse (seed bar: h = 2 cm, 8 particles per cell; copper: h = 0.8 mm,
// 8 per cell). SURGE_TAYLOR_FULL=1 runs the scenes as committed instead; SURGE_TAYLOR_CSV=<dir>
// writes the histories there (scripts/plot_taylor_bar.py plots them).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "support/run_scene.h"

namespace surge {
namespace {

struct Sample {
  Real t;        // [s]
  Real height;   // H [m]
  Real radius;   // R from the contact-layer centroid [m]
  Real outer;    // outermost extent of the contact layer [m] (secondary measure)
  Real kinetic;  // kinetic energy of the quarter model [J]
};

struct TaylorRun {
  std::vector<Sample> samples;  // every step, starting with t = 0
  Real max_plastic_strain = 0;  // at the end [-]
  size_t particles = 0;
  int64_t steps = 0;
  double seconds = 0;  // wall time of the run
};

bool FullResolution() {
  const char* full = std::getenv("SURGE_TAYLOR_FULL");
  return full != nullptr && std::string(full) == "1";
}

// H, R and the kinetic energy of the current state. `top` flags the ids of the initial top layer.
// The contact set is the particles now within one particle spacing s of the wall (z < s; at t = 0
// exactly the bottom layer). Tracking the initial bottom layer by id instead overstates R: those
// particles spread into a ring at the rim while particles from higher layers reach the wall at
// the centre, so their centroid is no longer that of a filled quarter disk.
Sample Measure(const State& s, Real spacing, const std::vector<char>& top) {
  const Particles& P = s.particles;
  Real top_z = 0, top_n = 0, mass = 0, mx = 0, my = 0, outer = 0, kinetic = 0;
  for (size_t p = 0; p < P.size(); ++p) {
    kinetic += 0.5 * P.mass[p] * P.v[p].squaredNorm();
    if (top[P.id[p]]) {
      top_z += P.x[p].z();
      top_n += 1;
    }
    if (P.x[p].z() < spacing) {
      mass += P.mass[p];
      mx += P.mass[p] * P.x[p].x();
      my += P.mass[p] * P.x[p].y();
      // Half-extent along the radial direction e_r of the particle's deformed cube F [-s/2, s/2]^3:
      // (s/2) sum_j |(F^T e_r)_j|.
      const Vec3 r(P.x[p].x(), P.x[p].y(), 0);
      const Real rn = r.norm();
      if (rn > 0) {
        const Vec3 e = r / rn;
        const Vec3 Fte = P.F[p].transpose() * e;
        outer = std::max(outer, rn + 0.5 * spacing * Fte.cwiseAbs().sum());
      }
    }
  }
  // Seed eqs. (7.3)-(7.4): x̄ = ȳ = 4R/(3π) for a quarter disk; x̄ and ȳ are averaged.
  const Real centroid = 0.5 * (mx + my) / mass;
  return Sample{s.time, top_z / top_n + 0.5 * spacing, 3 * M_PI / 4 * centroid, outer, kinetic};
}

// Scene overrides: the coarse CI set unless SURGE_TAYLOR_FULL=1, then any extra overrides from
// SURGE_TAYLOR_SET (comma-separated key=value, as `surge run --set`; for sensitivity studies).
std::vector<std::string> Overrides(const std::vector<std::string>& coarse) {
  const std::vector<std::string> out = testing::EnvOverrides(
      "SURGE_TAYLOR_SET", FullResolution() ? std::vector<std::string>{} : coarse);
  for (const std::string& o : out) std::printf("  --set %s\n", o.c_str());
  return out;
}

TaylorRun RunTaylor(const std::string& file, const std::vector<std::string>& overrides, Real H0) {
  LoadedScene scene = LoadScene(testing::ScenePath(file), overrides);
  const Particles& P = scene.state.particles;
  const Real spacing = std::cbrt(P.volume0.at(0));  // volume0 = s^3 (docs/scene-reference.md)
  std::vector<char> top(P.size(), 0);
  for (size_t p = 0; p < P.size(); ++p) top[P.id[p]] = P.x[p].z() > H0 - spacing;
  TaylorRun run;
  run.particles = P.size();
  run.samples.push_back(Measure(scene.state, spacing, top));
  const auto start = std::chrono::steady_clock::now();
  testing::RunUntil(scene, scene.model.time.end, [&](const State& s, const StepReport&) {
    run.samples.push_back(Measure(s, spacing, top));
  });
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.steps = scene.state.step;
  const HistoryArray& history = scene.state.particles.history;
  for (size_t p = 0; p < history.size(); ++p)
    run.max_plastic_strain = std::max(run.max_plastic_strain, history[p][kPlasticStrainSlot]);
  return run;
}

// The first sample at or after time t.
const Sample& At(const TaylorRun& run, Real t) {
  for (const Sample& s : run.samples)
    if (s.t >= t * (1 - 1e-9)) return s;
  return run.samples.back();
}

// Writes about `rows` evenly spaced samples as CSV when SURGE_TAYLOR_CSV names a directory.
void WriteCsv(const TaylorRun& run, const std::string& name, const std::string& header, Real t_unit,
              Real H0, Real R0, int rows) {
  const char* dir = std::getenv("SURGE_TAYLOR_CSV");
  if (dir == nullptr) return;
  const std::string path = std::string(dir) + "/" + name;
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr) << path;
  std::fprintf(f, "%s\n", header.c_str());
  const Real t_end = run.samples.back().t;
  Real next = 0;
  for (size_t i = 0; i < run.samples.size(); ++i) {
    const Sample& s = run.samples[i];
    if (s.t < next && i + 1 < run.samples.size()) continue;
    std::fprintf(f, "%.6g,%.6f,%.6f,%.6f,%.6g\n", s.t / t_unit, s.height / H0, s.radius / R0,
                 s.outer / R0, s.kinetic / run.samples.front().kinetic);
    next = s.t + t_end / rows;
  }
  std::fclose(f);
  std::printf("wrote %s\n", path.c_str());
}

// ---- Seed bar (Table 7.1) ----
constexpr Real kSeedH0 = 0.28, kSeedR0 = 0.04, kSeedEnd = 1.0e-3;

// Full-resolution result (scenes/taylor_bar_3d.yaml as committed: h = 1 cm, 27 per cell,
// measured with SURGE_TAYLOR_FULL=1, docs/taylor_bar.md): H̄ and R̄ at T = 1.
constexpr Real kSeedFullH = 0.7121, kSeedFullR = 1.748;

TEST(TaylorBarTest, SeedBarRunsStablyAndShortensMonotonically) {
  const bool full = FullResolution();
  const std::vector<std::string> coarse = {"grid.cell_size=0.02", "bodies.0.particles_per_cell=2"};
  const TaylorRun run = RunTaylor("taylor_bar_3d.yaml", Overrides(coarse), kSeedH0);
  ASSERT_GE(run.samples.back().t, kSeedEnd * (1 - 1e-9));  // healthy to t_f (RunUntil asserts)

  const Sample& s0 = run.samples.front();
  std::printf("seed Taylor bar (%s): %zu particles, %lld steps, %.1f s; R̄(0) = %.4f\n",
              full ? "h = 1 cm, 27 per cell" : "h = 2 cm, 8 per cell", run.particles,
              static_cast<long long>(run.steps), run.seconds, s0.radius / kSeedR0);
  for (Real T : {0.25, 0.5, 0.75, 1.0}) {
    const Sample& s = At(run, T * kSeedEnd);
    std::printf("  T = %.2f: H̄ = %.4f, R̄ = %.4f (outer extent %.4f), KE/KE0 = %.4f\n", T,
                s.height / kSeedH0, s.radius / kSeedR0, s.outer / kSeedR0,
                s.kinetic / s0.kinetic);
  }
  std::printf("  max equivalent plastic strain at T = 1: %.3f\n", run.max_plastic_strain);
  WriteCsv(run, full ? "taylor_bar_seed_full.csv" : "taylor_bar_seed_coarse.csv",
           "T,H_bar,R_bar,R_outer_bar,KE_ratio", kSeedEnd, kSeedH0, kSeedR0, 200);

  // H̄ never rises above its running minimum by more than the noise band: 0.5 % of H0 (0.14 of a
  // particle spacing at h = 2 cm; elastic ringing of the rear is ~ sigma_Y/E = 0.1 %).
  Real lowest = s0.height;
  for (const Sample& s : run.samples) {
    EXPECT_LE(s.height, lowest + 0.005 * kSeedH0) << "H rose at T = " << s.t / kSeedEnd;
    lowest = std::min(lowest, s.height);
  }
  const Sample& s25 = At(run, 0.25 * kSeedEnd);
  const Sample& s1 = run.samples.back();
  // Height at T = 1 within 3 % of the full-resolution run: the spec's smoke-test band for this
  // coarse variant (seed-validation-cases.md §4.1 [REC]); measured +0.65 % at h = 2 cm.
  EXPECT_NEAR(s1.height / kSeedH0, kSeedFullH, 0.03 * kSeedFullH);
  // The foot spreads throughout. Plain MPM's radius depends on the grid (h = 2 cm: R̄(1) = 2.08,
  // h = 1 cm: 1.75), so R̄ is gated only on growth and on exceeding 1.3 (a foot formed at all).
  EXPECT_GT(s25.radius, s0.radius);
  EXPECT_GT(s1.radius, s25.radius);
  EXPECT_GT(s1.radius / kSeedR0, 1.3) << "full-resolution R̄(1) = " << kSeedFullR;
}

// Anti-locking of an elastoplastic (J2) body (seed §4.4.5: the trial elastic strain is projected;
// seed Fig. 7.2): at the CI resolution node- and cell-based AS1 widen the foot of the seed bar,
// as the seed's anti-locked variants widen it against standard MPM, while the heights agree
// within 2 % (the seed: about 2 %). Measured 2026-12-03 (h = 2 cm, 8 per cell): outer extent at
// T = 1 plain 2.207 R0, node 2.427 (+10.0 %), cell 2.410 (+9.2 %); H̄(1) 0.7101 / 0.7103 / 0.7046.
// The full-resolution table is in docs/taylor_bar.md.
TEST(TaylorBarTest, AntiLockingWidensTheSeedBarFoot) {
  const std::vector<std::string> coarse = {"grid.cell_size=0.02", "bodies.0.particles_per_cell=2"};
  const auto run = [&](const std::string& antilocking) {
    std::vector<std::string> o = coarse;
    o.push_back("materials.aluminium.antilocking=" + antilocking);
    return RunTaylor("taylor_bar_3d.yaml", o, kSeedH0).samples.back();
  };
  const Sample plain = run("{method: none}");
  for (const std::string al : {"{method: node}", "{method: cell}"}) {
    const Sample s = run(al);
    std::printf("seed bar at T = 1, antilocking %s: outer extent %.4f R0 (plain %.4f), H̄ %.4f "
                "(plain %.4f)\n",
                al.c_str(), s.outer / kSeedR0, plain.outer / kSeedR0, s.height / kSeedH0,
                plain.height / kSeedH0);
    EXPECT_GT(s.outer, 1.05 * plain.outer) << al;
    EXPECT_GT(s.radius, plain.radius) << al;
    EXPECT_NEAR(s.height, plain.height, 0.02 * plain.height) << al;
  }
}

// ---- Copper bar (Kamoulakos 1990 benchmark) ----
constexpr Real kCuL0 = 0.0324, kCuR0 = 0.0032, kCuEnd = 8.0e-5;
// Published final length and foot radius [m]: reference FE solutions of this bilinear material
// (docs/taylor_bar.md, "Copper bar"); the middle of the quoted ranges.
constexpr Real kCuPublishedL = 0.021445, kCuPublishedR = 0.00705;

TEST(TaylorBarTest, CopperBarFinalShapeNearThePublishedBenchmark) {
  const bool full = FullResolution();
  const std::vector<std::string> coarse = {"grid.cell_size=0.0008", "bodies.0.particles_per_cell=2"};
  const TaylorRun run = RunTaylor("taylor_bar_copper_3d.yaml", Overrides(coarse), kCuL0);
  ASSERT_GE(run.samples.back().t, kCuEnd * (1 - 1e-9));

  const Sample& s0 = run.samples.front();
  const Sample& s1 = run.samples.back();
  std::printf("copper Taylor bar (%s): %zu particles, %lld steps, %.1f s\n",
              full ? "h = 0.4 mm, 27 per cell" : "h = 0.8 mm, 8 per cell", run.particles,
              static_cast<long long>(run.steps), run.seconds);
  for (Real t_us : {10.0, 20.0, 40.0, 60.0, 80.0}) {
    const Sample& s = At(run, t_us * 1e-6);
    std::printf("  t = %2.0f us: L = %.3f mm (L/L0 %.4f), R = %.3f mm (R/R0 %.4f), outer %.3f mm, "
                "KE/KE0 = %.4f\n",
                t_us, 1e3 * s.height, s.height / kCuL0, 1e3 * s.radius, s.radius / kCuR0,
                1e3 * s.outer, s.kinetic / s0.kinetic);
  }
  std::printf("  final length %.3f mm vs published %.3f mm (%+.2f %%); foot radius %.3f mm vs "
              "%.3f mm (%+.2f %%); outer extent %.3f mm (%+.2f %%); max plastic strain %.3f\n",
              1e3 * s1.height, 1e3 * kCuPublishedL, 100 * (s1.height / kCuPublishedL - 1),
              1e3 * s1.radius, 1e3 * kCuPublishedR, 100 * (s1.radius / kCuPublishedR - 1),
              1e3 * s1.outer, 100 * (s1.outer / kCuPublishedR - 1), run.max_plastic_strain);
  WriteCsv(run, full ? "taylor_bar_copper_full.csv" : "taylor_bar_copper_coarse.csv",
           "t_us,L_over_L0,R_over_R0,R_outer_over_R0,KE_ratio", 1e-6, kCuL0, kCuR0, 160);

  EXPECT_LT(s1.kinetic, 0.05 * s0.kinetic);  // the bar has stopped (elastic ringing only)
  // Tolerances from the runs in docs/taylor_bar.md (h = 0.8 mm, 8 per cell | h = 0.4 mm, 27 per
  // cell): length +1.71 % | +1.53 %; outer foot extent +1.3 % | -2.3 %; seed-centroid radius
  // -5.7 % | -9.9 % (the centroid of the layer within one spacing of the wall, which at finer
  // spacing includes more of the compressed centre). The outer extent is the like-for-like measure
  // of the FE "mushroom radius". Gates: 3 %, 5 % and 12 %.
  EXPECT_NEAR(s1.height, kCuPublishedL, 0.03 * kCuPublishedL);
  EXPECT_NEAR(s1.outer, kCuPublishedR, 0.05 * kCuPublishedR);
  EXPECT_NEAR(s1.radius, kCuPublishedR, 0.12 * kCuPublishedR);
}

// ---- OFHC copper against experiments (issue 3: "compare with a published copper Taylor-bar
// experiment") ----
// Measured rods, D0 = 7.62 mm, room temperature, as tabulated in B. Banerjee's compilation
// (github.com/bbanerjee/HighRateExptData, TaylorData/MATLAB/plotOFHCCu.m): Wilkins & Guinan 1973
// (J. Appl. Phys. 44:1200) and Johnson & Cook 1983 (as tabulated by Zerilli & Armstrong 1987,
// J. Appl. Phys. 61:1816). Df < 0: not measured.
struct CopperTest {
  const char* source;
  Real v0, L0, rho;    // [m/s], [m], [kg/m^3]
  Real lf_over_l0;     // measured final length / L0 [-]
  Real df_over_d0;     // measured foot diameter / D0 [-]
};
constexpr Real kOfhcD0 = 0.00762;
constexpr CopperTest kOfhcTests[] = {
    {"Wilkins & Guinan 1973", 89, 0.02347, 8900, 0.895, -1},
    {"Wilkins & Guinan 1973", 123, 0.02347, 8900, 0.835, -1},  // fitted
    {"Wilkins & Guinan 1973", 153, 0.02347, 8900, 0.780, -1},
    {"Wilkins & Guinan 1973", 183, 0.02347, 8900, 0.716, -1},
    {"Wilkins & Guinan 1973", 204, 0.02347, 8900, 0.669, -1},  // fitted
    {"Wilkins & Guinan 1973", 210, 0.02347, 8900, 0.643, 16.58e-3 / kOfhcD0},
    {"Johnson & Cook 1983", 130, 0.0254, 8920, 0.770, 1.30},
    {"Johnson & Cook 1983", 146, 0.0254, 8920, 0.736, 1.40},
    {"Johnson & Cook 1983", 190, 0.0254, 8920, 0.638, 1.78},
};

struct OfhcResult {
  Real lf_over_l0, df_over_d0, kinetic_ratio;
};

OfhcResult RunOfhc(const CopperTest& c) {
  char v0[64], l0[64], rho[64];
  std::snprintf(v0, sizeof v0, "parameters.v0=%.17g", c.v0);
  std::snprintf(l0, sizeof l0, "parameters.L0=%.17g", c.L0);
  std::snprintf(rho, sizeof rho, "parameters.rho=%.17g", c.rho);
  // CI resolution: h = 0.8 mm (4.8 cells across the radius), 2 particles per cell per axis.
  const std::vector<std::string> coarse = {"grid.cell_size=0.0008", "bodies.0.particles_per_cell=2"};
  std::vector<std::string> overrides = {v0, l0, rho};
  for (const std::string& o : Overrides(coarse)) overrides.push_back(o);
  const TaylorRun run = RunTaylor("taylor_bar_ofhc_3d.yaml", overrides, c.L0);
  const Sample& s0 = run.samples.front();
  const Sample& s1 = run.samples.back();
  const OfhcResult r{s1.height / c.L0, 2 * s1.outer / kOfhcD0, s1.kinetic / s0.kinetic};
  std::printf("OFHC copper, %s, v0 = %.0f m/s, L0 = %.2f mm (%zu particles, %.1f s): L_f/L0 = "
              "%.4f (measured %.3f, %+.2f %%)",
              c.source, c.v0, 1e3 * c.L0, run.particles, run.seconds, r.lf_over_l0, c.lf_over_l0,
              100 * (r.lf_over_l0 / c.lf_over_l0 - 1));
  if (c.df_over_d0 > 0)
    std::printf(", foot D_f/D0 = %.3f (measured %.3f, %+.2f %%)", r.df_over_d0, c.df_over_d0,
                100 * (r.df_over_d0 / c.df_over_d0 - 1));
  std::printf("; KE/KE0 %.4f\n", r.kinetic_ratio);
  return r;
}

// The scene's yield stress (230 MPa) and hardening slope (300 MPa) were chosen by hand from a
// small grid of runs at this resolution so that Wilkins & Guinan's lengths at 123 and 210 m/s
// match; the other rods are predictions. Measured 2026-12-05 (h = 0.8 mm, 8 per cell), L_f/L0
// against the experiment: Wilkins & Guinan 89 / 123 / 153 / 183 / 204 / 210 m/s: +1.63 / +0.31 /
// -1.17 / -1.80 / -1.89 / +0.04 %, foot diameter at 210 m/s -9.3 %; Johnson & Cook 130 / 146 /
// 190 m/s: +5.05 / +5.07 / +5.71 % (their copper is softer: at 190 m/s it shortens as much as
// Wilkins & Guinan's at 210), feet +19.1 / +17.4 / +5.1 %. The rods stop (KE < 0.7 % of KE0).
// CI runs the fitted 123 m/s rod and two predictions, Wilkins & Guinan's 210 m/s rod (the foot
// too; its length matched the fit) and Johnson & Cook's 190 m/s rod (another batch, length and
// density). Gates: lengths 3 % (Wilkins & Guinan) and 8 % (Johnson & Cook), feet 12 %.
// SURGE_TAYLOR_OFHC_ALL=1 runs all nine rods (about 70 s).
TEST(TaylorBarTest, OfhcCopperRodsMatchTheMeasuredFinalShapes) {
  const char* all = std::getenv("SURGE_TAYLOR_OFHC_ALL");
  const bool every = all != nullptr && std::string(all) == "1";
  for (const CopperTest& c : kOfhcTests) {
    const bool ci = (c.v0 == 123 || c.v0 == 210 || c.v0 == 190);
    if (!every && !ci) continue;
    const OfhcResult r = RunOfhc(c);
    EXPECT_LT(r.kinetic_ratio, 0.05) << c.source << " " << c.v0;  // the rod has stopped
    const bool wilkins = c.L0 < 0.024;
    EXPECT_NEAR(r.lf_over_l0, c.lf_over_l0, (wilkins ? 0.03 : 0.08) * c.lf_over_l0)
        << c.source << " " << c.v0;
    if (c.df_over_d0 > 0 && (wilkins || c.v0 == 190)) {  // 130, 146 m/s: +17-19 %, printed
      EXPECT_NEAR(r.df_over_d0, c.df_over_d0, 0.12 * c.df_over_d0) << c.source << " " << c.v0;
    }
  }
}

}  // namespace
}  // namespace surge

// surge: command-line entry point (CLI11). Subcommands: run, check, info, forces, sweep.
#include <CLI/CLI.hpp>
#include <tbb/version.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "app/forces_command.h"
#include "app/run.h"
#include "app/scene_warnings.h"
#include "app/sweep_command.h"
#include "core/log.h"
#include "grid/sparse_grid.h"
#include "io/results_writer.h"
#include "scene/memory_estimate.h"
#include "scene/scene.h"
#include "step/stages.h"
#include "step/step.h"
#include "surge/version.h"
#include "transfer/transfer.h"

namespace surge {
namespace {

std::string JoinArgs(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    if (i) s += ' ';
    s += argv[i];
  }
  return s;
}

const char* ShapeName(ShapeFunction s) {
  switch (s) {
    case ShapeFunction::kLinear: return "linear";
    case ShapeFunction::kGimp: return "gimp";
    case ShapeFunction::kQuadraticBspline: return "quadratic_bspline";
    case ShapeFunction::kCubicBspline: return "cubic_bspline";
  }
  return "?";
}

// `surge check`: validate, seed, build the first grid and print what a run would cost.
int Check(const std::string& path, const std::vector<std::string>& overrides) {
  LoadedScene scene = LoadScene(path, overrides);
  const Model& m = scene.model;
  const Particles& P = scene.state.particles;
  SparseGrid grid;
  RebuildGrid(m, P, grid);
  StepContext ctx;
  ctx.dx = m.dx;
  ctx.inv_dx = 1 / m.dx;
  ParticleToGrid(m, ctx, P, grid);
  const Real dt = NextTimeStep(m, scene.state);
  const double steps = dt > 0 ? m.time.end / dt : 0;
  // Memory at the first step (scene/memory_estimate.h; the run refuses a scene whose estimate
  // exceeds the available memory before seeding it).
  const MemoryEstimate memory =
      EstimateMemory(double(P.size()), double(grid.block_count()), m.field_count, m.dim, P.layout,
                     StepScratchFor(m));
  std::printf("scene      %s (%s)\n", m.name.c_str(), path.c_str());
  std::printf("dimension  %d-D%s, cell size %g m, %s, %s\n", m.dim,
              m.dim == 2 ? " plane strain" : "", m.dx, ShapeName(m.shape),
              m.transfer == TransferScheme::kApic     ? "APIC"
              : m.transfer == TransferScheme::kFlip   ? "FLIP"
                                                      : "PIC/FLIP");
  std::printf("materials  %zu, bodies %zu\n", m.materials.size(), m.bodies.size());
  std::printf("particles  %zu\n", P.size());
  // Structures and what the force log will hold (docs/results-format.md, "Force series").
  const std::vector<ForceChannel> channels = ForceChannels(m);
  if (!channels.empty()) {
    size_t dynamic = 0, prescribed = 0;
    for (const Obstacle& o : m.obstacles) {
      dynamic += o.motion.kind == ObstacleMotionKind::kDynamic;
      prescribed += o.motion.kind == ObstacleMotionKind::kPrescribed;
    }
    std::string names;
    for (const ForceChannel& c : channels) names += (names.empty() ? "" : ", ") + c.name;
    std::printf("structures %zu obstacles (%zu prescribed, %zu dynamic), %zu sensors; force log: %s\n",
                m.obstacles.size(), prescribed, dynamic, m.sensors.size(), names.c_str());
  }
  std::printf("grid       %zu active blocks (%s nodes), %zu nodes with mass\n",
              grid.block_count(), m.dim == 3 ? "8^3" : "8^2", grid.ActiveNodeCount());
  std::printf("time step  %.4g s (CFL %.2f) -> about %.0f steps to t = %g s\n", dt, m.time.cfl,
              steps, m.time.end);
  const Real dt_viscous = ViscousTimeStep(m, scene.state);
  if (std::isfinite(dt_viscous)) {
    std::printf("           viscous limit %.4g s (%s)\n", dt_viscous,
                m.time.fixed_dt > 0           ? "not applied: time.fixed_dt"
                : dt_viscous <= dt * 1.000001 ? "governs"
                                              : "not binding");
  }
  std::printf("memory     about %s (particles %s: %.0f bytes each; grid %s: %.0f bytes a block), "
              "%s available\n",
              FormatBytes(memory.total()).c_str(), FormatBytes(memory.particle_bytes).c_str(),
              BytesPerParticle(P.layout, StepScratchFor(m)), FormatBytes(memory.grid_bytes).c_str(),
              BytesPerBlock(m.field_count, m.dim, StepScratchFor(m)), FormatBytes(AvailableMemory()).c_str());
  for (const std::string& w : SceneWarnings(scene)) std::printf("warning    %s\n", w.c_str());
  std::printf("scene OK\n");
  return kExitOk;
}

int Info() {
  std::printf("surge %s (git %s)\n", SURGE_VERSION, SURGE_GIT_HASH);
#ifdef NDEBUG
  std::printf("build      release, C++%ld, GCC %d.%d\n", __cplusplus / 100 % 100, __GNUC__,
              __GNUC_MINOR__);
#else
  std::printf("build      debug, C++%ld, GCC %d.%d\n", __cplusplus / 100 % 100, __GNUC__,
              __GNUC_MINOR__);
#endif
  std::printf("precision  float64 particles and grid\n");
  std::printf("threads    %u hardware threads (oneTBB %d.%d)\n", std::thread::hardware_concurrency(),
              TBB_VERSION_MAJOR, TBB_VERSION_MINOR);
  std::printf("OpenVDB    %s\n", OpenVdbVersion());
  std::printf("HDF5       %s\n", Hdf5Version().c_str());
  std::printf("Eigen      %d.%d.%d\n", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
  std::printf("CLI11      %s\n", CLI11_VERSION);
  std::printf("shape functions: linear, gimp, quadratic_bspline, cubic_bspline\n");
  std::printf("transfers:       flip, pic_flip, apic;  updates: usl, musl\n");
  std::string models;
  for (const std::string& name : MaterialModelNames()) models += (models.empty() ? "" : ", ") + name;
  std::printf("materials:       %s\n", models.c_str());
  return kExitOk;
}

int Main(int argc, char** argv) {
  CLI::App app{"Surge: material point method impact simulator"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("surge ") + SURGE_VERSION);

  std::string scene_path, out_dir;
  int threads = 0;
  std::vector<std::string> overrides;
  bool quiet = false, verbose = false;
  std::string progress = "auto";

  CLI::App* run = app.add_subcommand("run", "Run a scene and write results (HDF5 + XDMF)");
  run->add_option("scene", scene_path, "Scene file (YAML)")->required();
  run->add_option("--out,-o", out_dir, "Results folder (default: results/<scene name>)");
  run->add_option("--threads,-t", threads, "Worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  run->add_option("--set", overrides, "Override a scene value: key.path=value (repeatable)");
  run->add_option("--progress", progress, "Progress output: auto, terminal, plain, quiet")
      ->check(CLI::IsMember({"auto", "terminal", "plain", "quiet"}));
  run->add_flag("--quiet,-q", quiet, "Only errors and the summary");
  run->add_flag("--verbose,-v", verbose, "Debug log messages");
  bool force = false;
  std::string restart;
  int64_t stop_at_step = -1;
  run->add_flag("--force", force, "Overwrite an existing result in the results folder");
  run->add_option("--restart", restart,
                  "Continue the run from a checkpoint (<out>/checkpoints/<name>_step_N.h5)");
  // Testing only (tests/regression/restart_test.sh): stop as on Ctrl-C after this step.
  run->add_option("--stop-at-step", stop_at_step, "")->group("")->check(CLI::NonNegativeNumber);

  CLI::App* check = app.add_subcommand("check", "Validate a scene and estimate its cost");
  check->add_option("scene", scene_path, "Scene file (YAML)")->required();
  check->add_option("--set", overrides, "Override a scene value: key.path=value (repeatable)");

  CLI::App* info = app.add_subcommand("info", "Version, build options and library versions");

  ForcesCommandOptions forces_options;
  CLI::App* forces = AddForcesSubcommand(app, forces_options);

  SweepCommandOptions sweep_options;
  CLI::App* sweep = AddSweepSubcommand(app, sweep_options);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }
  SetLogLevel(verbose ? LogLevel::kDebug : quiet ? LogLevel::kWarn : LogLevel::kInfo);

  try {
    if (*info) return Info();
    if (*check) return Check(scene_path, overrides);
    if (*forces) return ForcesCommand(forces_options);
    if (*sweep) return SweepCommand(sweep_options);
    RunOptions options;
    auto resolve_out_dir = [&](const std::string& name) {
      options.out_dir = out_dir.empty() ? "results/" + name : out_dir;
      // A restart continues the result next to its checkpoint (<out>/checkpoints/...).
      const std::filesystem::path checkpoint_dir = std::filesystem::path(restart).parent_path();
      if (out_dir.empty() && !restart.empty() && checkpoint_dir.filename() == "checkpoints") {
        options.out_dir =
            checkpoint_dir.parent_path().empty() ? "." : checkpoint_dir.parent_path().string();
      }
      // Refused before the particles are seeded (RunScene checks again).
      if (restart.empty()) CheckNewRunAllowed(options.out_dir, name, force);
    };
    LoadedScene scene = LoadScene(scene_path, overrides, resolve_out_dir);
    options.force = force;
    options.restart = restart;
    options.stop_at_step = stop_at_step;
    options.threads = threads;
    options.command_line = JoinArgs(argc, argv);
    options.progress = quiet                    ? ProgressMode::kQuiet
                       : progress == "terminal" ? ProgressMode::kTerminal
                       : progress == "plain"    ? ProgressMode::kPlain
                       : progress == "quiet"    ? ProgressMode::kQuiet
                                                : ProgressMode::kAuto;
    for (const std::string& w : SceneWarnings(scene)) LogWarn(w);
    LogInfo("running " + scene.model.name + ": " + std::to_string(scene.state.particles.size()) +
            " particles, results in " + options.out_dir);
    const RunSummary summary = RunScene(scene, options);
    PrintSummary(scene, summary);
    return summary.exit_code;
  } catch (const SceneError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const RunRefused& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitFailure;
  }
}

}  // namespace
}  // namespace surge

int main(int argc, char** argv) { return surge::Main(argc, argv); }

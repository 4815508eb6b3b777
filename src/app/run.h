// The frame loop of `surge run`: steps, output cadence, progress, Ctrl-C, exit codes.
#pragma once
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/force_summary.h"

#include "core/math.h"

namespace surge {

struct LoadedScene;

// Exit codes of `surge run` (also documented in docs/getting-started.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,      // unexpected error (I/O, internal check)
  kExitBadInput = 2,     // scene or command-line error
  kExitUnhealthy = 3,    // the health check stopped the run (NaN, inverted particle, left domain)
  kExitInterrupted = 130 // Ctrl-C: current step finished, results flushed
};

enum class ProgressMode { kAuto, kTerminal, kPlain, kQuiet };

struct RunOptions {
  std::string out_dir;       // results folder
  int threads = 0;           // 0 = all cores
  ProgressMode progress = ProgressMode::kAuto;
  std::string command_line;  // recorded in the results
  bool force = false;        // overwrite an existing result <out_dir>/<name>.h5
  std::string restart;       // checkpoint to continue from (io/checkpoint.h); "" = a new run
  // Testing (hidden --stop-at-step): once this many steps are completed, stop as on Ctrl-C
  // (checkpoint, flush, exit 130). -1 = never.
  int64_t stop_at_step = -1;
};

// A run refused before it starts for a reason the user can fix on the command line (an existing
// result without --force, a checkpoint of another scene): exit code kExitBadInput.
struct RunRefused : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RunSummary {
  int exit_code = kExitOk;
  std::string exit_status;     // "completed", "interrupted", or the health diagnostic
  int64_t steps = 0;
  double wall_seconds = 0;
  double particle_updates_per_second = 0;
  Real end_time = 0;
  // Peak and impulse of every logged structure (domain walls, obstacles), every step counted.
  std::vector<ForceChannel> force_channels;
  std::vector<StructurePeak> force_peaks;  // as force_channels
  std::string h5_path, xmf_path;
  int snapshots = 0;
  // <out>/summary.json (`surge forces --json` of the result; "" if it could not be written) and
  // the main numbers of its analysis, as printed.
  std::string summary_json_path;
  std::vector<std::string> analysis_lines;
};

// Runs the scene into options.out_dir, or continues the run of options.restart there (the
// result is cut back to the checkpoint and continued; docs/results-format.md, "Checkpoints").
// Throws RunRefused when `<out_dir>/<name>.h5` exists and `force` is false, naming --force,
// --out and the newest checkpoint to --restart from. RunScene checks it again; `surge run` calls
// it before the scene is built (LoadScene's before_build).
void CheckNewRunAllowed(const std::string& out_dir, const std::string& name, bool force);

// Throws RunRefused for an existing result without options.force, and for a checkpoint whose
// scene (text or --set overrides) is not `scene`.
RunSummary RunScene(LoadedScene& scene, const RunOptions& options);

// Prints the end-of-run summary (results location, steps, speed, wall forces, energies).
void PrintSummary(const LoadedScene& scene, const RunSummary& summary);

}  // namespace surge

// The frame loop of `surge run`: steps, output cadence, progress, Ctrl-C, exit codes.
#pragma once
#include <array>
#include <cstdint>
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

RunSummary RunScene(LoadedScene& scene, const RunOptions& options);

// Prints the end-of-run summary (results location, steps, speed, wall forces, energies).
void PrintSummary(const LoadedScene& scene, const RunSummary& summary);

}  // namespace surge

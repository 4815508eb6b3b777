// `surge forces RESULT.h5`: the force analysis of a finished run (issue #6; docs/forces.md):
// peak, impulse, steady state and the seed's coefficients, as a table or JSON. `surge run`
// writes the same JSON as <out>/summary.json (docs/results-format.md, "summary.json").
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/analysis.h"

namespace CLI {
class App;
}

namespace surge {

// What the command line changes in the scene's `analysis` section (unset = as in the scene).
struct ForcesCommandOptions {
  std::string result_path;
  std::string structure;  // --obstacle: a structure of the force log (clears the scene's face)
  std::string face;       // --face
  std::string component;  // --component x|y|z|normal|magnitude
  bool json = false;      // --json
  ReferenceValues reference;   // --velocity --density --width --height --area --k0 --gravity
  std::string smooth;          // --smooth none | moving_average=S | exponential=TAU | low_pass=HZ
  std::optional<int> order;    // --order 1|2 (low_pass)
  std::optional<Real> average, min_window, tolerance;  // --average --min-window --tolerance
  std::vector<Real> window;    // --window T0 T1
};

// Adds the `forces` subcommand and its options to `app`; ForcesCommand runs it.
CLI::App* AddForcesSubcommand(CLI::App& app, ForcesCommandOptions& options);

// Runs `surge forces`: prints the table or the JSON; returns the exit code (kExitOk,
// kExitBadInput for a missing or foreign file, an unknown structure or face, bad options).
int ForcesCommand(const ForcesCommandOptions& options);

// The JSON document of `surge forces --json` for a results file (summary.json). Throws
// IoError for an unreadable or foreign file and std::invalid_argument for unknown names or
// impossible settings. `lines`, if given, receives the few lines `surge run` prints.
std::string ForcesSummaryJson(const ForcesCommandOptions& options,
                              std::vector<std::string>* lines = nullptr);

}  // namespace surge

// `surge sweep SWEEP.yaml`: run the cases of a sweep file (docs/sweeps.md) as child `surge run`
// processes, N at a time, resumably, and collect one CSV row per case.
#pragma once
#include <string>

namespace CLI {
class App;
}

namespace surge {

struct SweepCommandOptions {
  std::string sweep_path;
  std::string out;          // --out: overrides the sweep file's `out`
  int jobs = 0;             // --jobs: cases at a time; 0 = the file's `jobs` or cores / threads
  bool dry_run = false;     // list the cases and their overrides, run nothing
  bool force = false;       // rerun completed cases too
  bool collect = false;     // only (re)build <out>/sweep.csv from the case folders
  int case_index = -1;      // --case I: run only case I (a Slurm array task)
  std::string slurm_path;   // --slurm FILE: write a job-array script, run nothing
};

// Adds the `sweep` subcommand and its options to `app`; SweepCommand runs it.
CLI::App* AddSweepSubcommand(CLI::App& app, SweepCommandOptions& options);

// Runs `surge sweep`; returns the exit code (kExitOk, kExitFailure when a case failed,
// kExitInterrupted after Ctrl-C). Throws SceneError for a bad sweep file or case.
int SweepCommand(const SweepCommandOptions& options);

}  // namespace surge

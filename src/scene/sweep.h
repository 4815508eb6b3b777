// Sweep files (docs/sweeps.md): a base scene plus --set overrides, expanded into cases as a
// cartesian product of parameter values or as an explicit list. Also the small YAML/JSON helpers
// of `surge sweep` (the per-case record, the flattened summary.json), so that yaml-cpp stays in
// surge_scene. The runner is src/app/sweep_command.cpp.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace surge {

// One --set override of a case and where the sweep file gave it (for errors).
struct SweepOverride {
  std::string text;  // "key.path=value", as `surge run --set` takes it
  int line = 0;      // 1-based position of the value in the sweep file; 0 = none
  int column = 0;
};

struct SweepCase {
  int index = 0;     // 0-based; also the Slurm array task id
  std::string name;  // folder name: case_003_wc=2_phi=20 (deterministic, unique)
  // The value of every sweep column (SweepSpec::columns, same order) as YAML text; "" where
  // a list-mode case does not set that column.
  std::vector<std::string> values;
  // In application order: the sweep-wide `set`, then the case's own overrides (later wins).
  std::vector<SweepOverride> overrides;
};

enum class SweepMode { kProduct, kList };

struct SweepSpec {
  std::string path;       // the sweep file, as given
  std::string base;       // the base scene, relative to the sweep file's folder resolved
  std::string out;        // results folder (relative paths: from the current directory)
  SweepMode mode = SweepMode::kProduct;
  int threads_per_case = 1;
  int jobs = 0;           // default for --jobs; 0 = cores / threads_per_case
  std::vector<std::string> columns;  // CSV columns: parameter key paths or linked names
  std::vector<SweepCase> cases;
};

// Reads and expands a sweep file. Throws SceneError (file:line:column: key: message) on unknown
// keys, wrong types, empty value lists and duplicate case names. Does not load the base scene:
// the runner validates every case with LoadScene.
SweepSpec LoadSweepFile(const std::string& path);

// As LoadSweepFile, from text; `source` names the file in errors and gives the default `out`
// (its stem); `base_dir` is the folder that a relative `base` is taken from.
SweepSpec ParseSweepText(const std::string& text, const std::string& source,
                         const std::string& base_dir);

// What `surge sweep` knows about a case after running it: <case dir>/case.yaml.
struct SweepCaseRecord {
  std::string name;
  int index = 0;
  std::string scene;                   // the base scene path the case ran
  std::vector<std::string> overrides;  // the --set texts, in order
  std::string scene_digest;            // of the resolved scene it ran ("" = unknown)
  std::string status;                  // "running", "completed", "failed", ...
  int exit_code = -1;                  // of `surge run`; -1 while running
  double wall_seconds = 0;             // measured by the sweep [s]
};

// Writes the record (overwriting). Throws std::runtime_error when the file cannot be written.
void WriteSweepCaseRecord(const std::string& path, const SweepCaseRecord& record);
// Reads a record; false when the file is missing or not a record.
bool ReadSweepCaseRecord(const std::string& path, SweepCaseRecord& record);

// Every numeric or string leaf of a JSON (or YAML) file as (dotted path, text), in file order:
// {"column": {"peak": {"force": [1, 2, 3]}}} gives column.peak.force.x/.y/.z (lists of 2 or 3
// numbers are vectors), other lists index their items (.0, .1, ...); null gives "". Empty when
// the file is missing; throws SceneError when it cannot be parsed.
std::vector<std::pair<std::string, std::string>> FlattenJsonFile(const std::string& path);

}  // namespace surge

// `surge sweep`: validate every case of a sweep file, run them as child processes of this same
// executable (`surge run ... --out <case dir>`), N at a time, skip the ones already completed,
// and write <out>/sweep.csv. Also --case I (one case: a Slurm array task), --collect (the CSV
// only), --slurm FILE (a job-array script) and --dry-run. Format and behaviour: docs/sweeps.md.
#include "app/sweep_command.h"

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/run.h"
#include "core/hash.h"
#include "io/checkpoint.h"
#include "io/result_status.h"
#include "scene/scene.h"
#include "scene/sweep.h"

extern char** environ;

namespace surge {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::atomic<int> g_stop_requests{0};  // SIGINT / SIGTERM received by the sweep

extern "C" void OnStopSignal(int) { g_stop_requests.fetch_add(1); }

std::string ExePath() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot find the surge executable (/proc/self/exe): " + ec.message());
  return p.string();
}

std::string Absolute(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::absolute(path, ec);
  return (ec ? fs::path(path) : p).lexically_normal().string();
}

// Single-quoted for sh: 'it'\''s'.
std::string ShellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string CsvCell(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string Duration(double seconds) {
  char buf[32];
  const long s = std::lround(std::max(0.0, seconds));
  if (s >= 3600) {
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, s / 60 % 60);
  } else if (s >= 60) {
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buf, sizeof buf, "%lds", s);
  }
  return buf;
}

std::vector<std::string> OverrideTexts(const SweepCase& c) {
  std::vector<std::string> texts;
  for (const SweepOverride& o : c.overrides) texts.push_back(o.text);
  return texts;
}

// What validating a case tells about it.
struct CaseScene {
  std::string h5_name;  // "<scene name>.h5"
  std::string digest;   // SceneDigest of the case's resolved scene
};

// FNV-1a (64 bit) of the resolved scene (every key, defaults filled in, after the overrides and
// expressions), in hex: a case whose scene changed since it ran is outdated. Comments and
// layout of the scene file do not count; the mesh files do, through their content hashes in it.
std::string SceneDigest(const std::string& resolved_yaml) { return Fnv1aHex(resolved_yaml); }

// Everything known about one case: its folder, how it last ran, its summary.
struct CaseView {
  const SweepCase* c = nullptr;
  std::string dir;         // <out>/<case name>
  std::string digest;      // of the scene it will run (validated); "" when not validated
  std::string h5;          // results file; "" until known
  std::string status;      // completed, failed, unhealthy, interrupted, incomplete, outdated, not_run
  int exit_code = -1;
  double wall_seconds = 0;
  std::string detail;      // why it is not completed
  std::string resumed_from;  // the checkpoint the running case continues from; "" if from t = 0
};

// Reads the state of case `c` from its folder. `known` comes from validating the case; without
// it (--collect) the results file is the folder's only .h5 and the scene is not compared.
CaseView InspectCase(const SweepSpec& spec, const SweepCase& c, const CaseScene& known) {
  CaseView v;
  v.c = &c;
  v.dir = (fs::path(spec.out) / c.name).string();
  v.digest = known.digest;
  SweepCaseRecord record;
  const bool has_record = ReadSweepCaseRecord((fs::path(v.dir) / "case.yaml").string(), record);
  std::string name = known.h5_name;
  std::error_code ec;
  if (name.empty() && fs::is_directory(v.dir, ec)) {
    for (const auto& e : fs::directory_iterator(v.dir, ec)) {
      if (e.path().extension() == ".h5") name = name.empty() ? e.path().filename().string() : "?";
    }
  }
  v.h5 = name.empty() || name == "?" ? "" : (fs::path(v.dir) / name).string();
  const ResultStatus rs = v.h5.empty() ? ResultStatus{} : ReadResultStatus(v.h5);
  const bool completed = rs.closed && rs.exit_status == "completed";

  if (has_record && record.overrides != OverrideTexts(c)) {
    v.status = "outdated";
    v.detail = "ran with other overrides: " + std::to_string(record.overrides.size()) + " --set";
    return v;
  }
  if (has_record && !v.digest.empty() && !record.scene_digest.empty() && record.scene_digest != v.digest) {
    v.status = "outdated";
    v.detail = "the base scene changed since it ran";
    return v;
  }
  v.wall_seconds = has_record ? record.wall_seconds : rs.wall_seconds;
  v.exit_code = has_record ? record.exit_code : (completed ? 0 : -1);
  if (has_record && record.exit_code >= 0) {
    if (record.exit_code == kExitOk) {
      v.status = completed ? "completed" : "failed";
      if (!completed) v.detail = "no completed results file";
    } else if (record.exit_code == kExitInterrupted) {
      v.status = "interrupted";
      v.detail = rs.closed ? rs.exit_status : "interrupted";
    } else if (record.exit_code == kExitUnhealthy) {
      v.status = "unhealthy";
      v.detail = rs.closed ? rs.exit_status : "stopped by the health check";
    } else {
      v.status = "failed";
      v.detail = "exit code " + std::to_string(record.exit_code);
    }
  } else if (completed) {
    v.status = "completed";
  } else if (has_record) {
    v.status = "incomplete";
    v.detail = "started but never finished";
  } else {
    v.status = "not_run";
  }
  return v;
}

// Writes <out>/sweep.csv: case, the sweep columns, status, exit code, wall time, detail, then
// every leaf of the case's summary.json (columns in order of first appearance).
std::string WriteCsv(const SweepSpec& spec, const std::vector<CaseView>& views) {
  std::vector<std::vector<std::pair<std::string, std::string>>> summaries;
  std::vector<std::string> extra;
  std::map<std::string, size_t> extra_index;
  for (const CaseView& v : views) {
    summaries.push_back(FlattenJsonFile((fs::path(v.dir) / "summary.json").string()));
    for (const auto& kv : summaries.back()) {
      if (extra_index.emplace(kv.first, extra.size()).second) extra.push_back(kv.first);
    }
  }
  fs::create_directories(spec.out);
  const std::string path = (fs::path(spec.out) / "sweep.csv").string();
  std::ofstream out(path, std::ios::trunc);
  out << "case";
  for (const std::string& c : spec.columns) out << "," << CsvCell(c);
  out << ",status,exit_code,wall_s,detail";
  for (const std::string& e : extra) out << "," << CsvCell(e);
  out << "\n";
  for (size_t i = 0; i < views.size(); ++i) {
    const CaseView& v = views[i];
    out << CsvCell(v.c->name);
    for (const std::string& value : v.c->values) out << "," << CsvCell(value);
    char wall[32];
    std::snprintf(wall, sizeof wall, "%.3f", v.wall_seconds);
    out << "," << v.status << "," << v.exit_code << "," << wall << "," << CsvCell(v.detail);
    std::vector<std::string> cells(extra.size());
    for (const auto& kv : summaries[i]) cells[extra_index.at(kv.first)] = kv.second;
    for (const std::string& cell : cells) out << "," << CsvCell(cell);
    out << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + path);
  return path;
}

// Loads every case's scene with its overrides (seeding included), so that a bad value fails
// before anything runs.
std::vector<CaseScene> ValidateCases(const SweepSpec& spec, const std::vector<const SweepCase*>& cases) {
  std::vector<CaseScene> scenes;
  for (const SweepCase* c : cases) {
    try {
      const LoadedScene scene = LoadScene(spec.base, OverrideTexts(*c));
      scenes.push_back({scene.model.name + ".h5", SceneDigest(scene.resolved_yaml)});
    } catch (const SceneError& e) {
      // Point at the sweep file's value when an override is to blame.
      int line = 0, column = 0;
      for (const SweepOverride& o : c->overrides) {
        if (e.file() == "--set " + o.text) line = o.line, column = o.column;
      }
      throw SceneError(spec.path, line, column, "", "case " + c->name + ": " + e.what());
    }
  }
  return scenes;
}

class Runner {
 public:
  Runner(const SweepSpec& spec, std::string exe) : spec_(spec), exe_(std::move(exe)) {}

  // Starts `surge run` for the case; its stdout and stderr go to <case dir>/log.txt. An
  // interrupted or incomplete case with a checkpoint of its own continues from the newest one
  // when `resume` (`surge run --restart`, bitwise the same result as an uninterrupted run);
  // otherwise it starts over.
  pid_t Start(CaseView& v, bool resume) {
    v.resumed_from.clear();
    if (resume && (v.status == "interrupted" || v.status == "incomplete") && !v.h5.empty()) {
      const std::vector<std::string> checkpoints =
          ListCheckpoints(v.dir, fs::path(v.h5).stem().string());
      if (!checkpoints.empty()) v.resumed_from = checkpoints.back();
    }
    fs::create_directories(v.dir);
    std::error_code ec;
    fs::remove(fs::path(v.dir) / "summary.json", ec);  // no stale summary if this run fails
    SweepCaseRecord record;
    record.name = v.c->name;
    record.index = v.c->index;
    record.scene = spec_.base;
    record.overrides = OverrideTexts(*v.c);
    record.scene_digest = v.digest;
    record.status = "running";
    WriteSweepCaseRecord((fs::path(v.dir) / "case.yaml").string(), record);

    // --force: the sweep decided that this case runs (again); an older result in its folder
    // (failed, interrupted, outdated) is replaced.
    std::vector<std::string> args = {exe_, "run", Absolute(spec_.base), "--out", v.dir,
                                     "--threads", std::to_string(spec_.threads_per_case),
                                     "--progress", "quiet"};
    if (v.resumed_from.empty()) {
      args.push_back("--force");
    } else {
      args.push_back("--restart");
      args.push_back(v.resumed_from);
    }
    for (const std::string& o : record.overrides) {
      args.push_back("--set");
      args.push_back(o);
    }
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    const std::string log = (fs::path(v.dir) / "log.txt").string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    // A resumed case appends to the log of the run it continues.
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(),
                                     O_WRONLY | O_CREAT | (v.resumed_from.empty() ? O_TRUNC : O_APPEND), 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    // Own process group: a terminal Ctrl-C reaches only the sweep, which passes it on to every
    // case; a SIGINT or SIGTERM sent to the sweep alone (kill, Slurm) stops the cases as well.
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t defaults, none;
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    sigemptyset(&none);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    pid_t pid = -1;
    // Executes /proc/self/exe (this very binary, even if it was rebuilt or deleted meanwhile);
    // argv[0] is its path for the logs.
    const int rc = posix_spawn(&pid, "/proc/self/exe", &actions, &attr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    if (rc != 0) throw std::runtime_error("cannot start " + exe_ + ": " + std::strerror(rc));
    return pid;
  }

  // Records how the case ended and reads its state back.
  void Finish(CaseView& v, int wait_status, double wall_seconds) {
    const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status)
                     : WIFSIGNALED(wait_status) ? 128 + WTERMSIG(wait_status)
                                                : kExitFailure;
    SweepCaseRecord record;
    record.name = v.c->name;
    record.index = v.c->index;
    record.scene = spec_.base;
    record.overrides = OverrideTexts(*v.c);
    record.scene_digest = v.digest;
    record.exit_code = code;
    record.wall_seconds = wall_seconds;
    record.status = code == kExitOk ? "completed" : "ended";
    WriteSweepCaseRecord((fs::path(v.dir) / "case.yaml").string(), record);
    const CaseScene known{v.h5.empty() ? "" : fs::path(v.h5).filename().string(), v.digest};
    v = InspectCase(spec_, *v.c, known);
  }

 private:
  const SweepSpec& spec_;
  std::string exe_;
};

struct SignalGuard {
  struct sigaction old_int {}, old_term {};
  SignalGuard() {
    g_stop_requests.store(0);
    struct sigaction sa {};
    sa.sa_handler = OnStopSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: a sleep ends early
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
};

std::string CaseLine(const CaseView& v) {
  std::string s = v.c->name + ": " + v.status;
  if (v.status == "completed" || v.exit_code >= 0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, " in %.1f s", v.wall_seconds);
    s += buf;
  }
  if (!v.detail.empty()) s += " (" + v.detail + ")";
  if (v.status != "completed") s += ", log: " + (fs::path(v.dir) / "log.txt").string();
  return s;
}

// Runs the cases `todo` (indices into views), `jobs` at a time. Returns true unless stopped.
// `resume`: interrupted cases continue from their newest checkpoint (Runner::Start).
bool RunCases(const SweepSpec& spec, std::vector<CaseView>& views, const std::vector<size_t>& todo,
              int jobs, int skipped, bool resume) {
  Runner runner(spec, ExePath());
  SignalGuard guard;
  const bool tty = isatty(STDERR_FILENO);
  struct Running {
    size_t view;
    pid_t pid;
    Clock::time_point start;
  };
  std::vector<Running> running;
  size_t next = 0, done = 0, failed = 0;
  int forwarded = 0;
  double wall_sum = 0;
  const Clock::time_point t0 = Clock::now();
  Clock::time_point last_line = t0;
  const size_t total = todo.size();

  auto progress = [&](bool force) {
    const Clock::time_point now = Clock::now();
    // A terminal gets the line redrawn on every change and every second; a log file a line a
    // minute (the finished cases have their own lines).
    if (!(force && tty) && now - last_line < std::chrono::seconds(tty ? 1 : 60)) return;
    last_line = now;
    std::string eta = "?";
    if (done > 0) {
      // Mean case wall time so far; the running cases count for what they still have to do.
      const double mean = wall_sum / double(done);
      double work = double(total - next) * mean;
      for (const Running& r : running) {
        work += std::max(0.0, mean - std::chrono::duration<double>(now - r.start).count());
      }
      eta = Duration(work / std::max(1, std::min<int>(jobs, int(total - done))));
    }
    std::fprintf(stderr, "%ssweep: %zu/%zu done, %zu running, %zu failed%s, elapsed %s, ETA %s%s",
                 tty ? "\r\033[K" : "", done, total, running.size(), failed,
                 skipped ? (", " + std::to_string(skipped) + " skipped").c_str() : "",
                 Duration(std::chrono::duration<double>(now - t0).count()).c_str(), eta.c_str(),
                 tty ? "" : "\n");
    std::fflush(stderr);
  };
  auto print = [&](const std::string& line) {
    if (tty) std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
  };

  while (true) {
    const int requests = g_stop_requests.load();
    if (requests > forwarded) {
      if (forwarded == 0) {
        print("sweep: stopping: the running cases finish their step and write their results; "
              "rerun the same command to resume");
      }
      for (const Running& r : running) kill(r.pid, SIGINT);
      forwarded = requests;
    }
    bool changed = false;
    while (forwarded == 0 && running.size() < size_t(jobs) && next < todo.size()) {
      CaseView& v = views[todo[next++]];
      running.push_back({size_t(&v - views.data()), runner.Start(v, resume), Clock::now()});
      if (!v.resumed_from.empty()) print(v.c->name + ": continuing from " + v.resumed_from);
      changed = true;
    }
    if (running.empty()) break;
    for (size_t i = 0; i < running.size();) {
      int status = 0;
      const pid_t r = waitpid(running[i].pid, &status, WNOHANG);
      if (r == 0 || (r < 0 && errno == EINTR)) {
        ++i;
        continue;
      }
      const double wall = std::chrono::duration<double>(Clock::now() - running[i].start).count();
      CaseView& v = views[running[i].view];
      // A checkpoint that `surge run --restart` refuses (exit 2: unreadable, or not this case's):
      // the case starts over instead.
      if (!v.resumed_from.empty() && r > 0 && WIFEXITED(status) && WEXITSTATUS(status) == kExitBadInput &&
          forwarded == 0) {
        print(v.c->name + ": " + v.resumed_from + " refused (see the log), starting over");
        running[i].pid = runner.Start(v, /*resume=*/false);
        continue;
      }
      runner.Finish(v, r < 0 ? (kExitFailure << 8) : status, wall);
      ++done;
      wall_sum += wall;
      failed += v.status != "completed";
      print("[" + std::to_string(done) + "/" + std::to_string(total) + "] " + CaseLine(v));
      running.erase(running.begin() + std::ptrdiff_t(i));
      changed = true;
    }
    progress(changed);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (tty) std::fprintf(stderr, "\r\033[K");
  return forwarded == 0;
}

std::string SlurmScript(const SweepSpec& spec, const SweepCommandOptions& o, const std::string& exe) {
  const std::string cwd = fs::current_path().string();
  const std::string sweep = Absolute(spec.path);
  const std::string out = Absolute(spec.out);
  std::string tail;
  if (!o.out.empty()) tail += " --out " + ShellQuote(out);
  std::string s;
  s += "#!/bin/bash\n";
  s += "# Slurm job array for the sweep " + spec.path + " (" + std::to_string(spec.cases.size()) +
       " cases), written by `surge sweep --slurm`.\n";
  s += "# One array task per case: task I runs case I (case_00I_...) with `surge sweep --case I`,\n";
  s += "# which skips a case that already completed. Submit the cases, then the table once they\n";
  s += "# have all ended:\n";
  s += "#   jobid=$(sbatch --parsable " + ShellQuote(o.slurm_path) + ")\n";
  s += "#   sbatch --dependency=afterany:$jobid --job-name=" + fs::path(spec.path).stem().string() +
       "-collect --wrap=\"cd " + ShellQuote(cwd) + " && " + ShellQuote(exe) + " sweep " +
       ShellQuote(sweep) + " --collect" + tail + "\"\n";
  s += "# Add your site's options (--time, --partition, --account, --mem) below.\n";
  s += "#SBATCH --job-name=" + fs::path(spec.path).stem().string() + "\n";
  s += "#SBATCH --array=0-" + std::to_string(spec.cases.size() - 1) + "\n";
  s += "#SBATCH --ntasks=1\n";
  s += "#SBATCH --cpus-per-task=" + std::to_string(spec.threads_per_case) + "\n";
  s += "#SBATCH --output=" + out + "/slurm_%A_%a.log\n";
  s += "set -eu\n";
  s += "cd " + ShellQuote(cwd) + "\n";
  s += "exec " + ShellQuote(exe) + " sweep " + ShellQuote(sweep) + " --case \"$SLURM_ARRAY_TASK_ID\"" +
       tail + (o.force ? " --force" : "") + "\n";
  return s;
}

int Summarise(const std::vector<CaseView>& views, const std::string& csv) {
  std::map<std::string, int> counts;
  for (const CaseView& v : views) ++counts[v.status];
  std::string line;
  for (const auto& [status, n] : counts) line += (line.empty() ? "" : ", ") + std::to_string(n) + " " + status;
  std::printf("sweep: %zu cases: %s; table: %s\n", views.size(), line.c_str(), csv.c_str());
  return counts["completed"] == int(views.size()) ? kExitOk : kExitFailure;
}

}  // namespace

CLI::App* AddSweepSubcommand(CLI::App& app, SweepCommandOptions& o) {
  CLI::App* sweep = app.add_subcommand("sweep", "Run a parametric sweep of a scene (docs/sweeps.md)");
  sweep->add_option("sweep", o.sweep_path, "Sweep file (YAML)")->required();
  sweep->add_option("--jobs,-j", o.jobs, "Cases run at a time (default: cores / threads_per_case)")
      ->check(CLI::Range(1, 4096));
  sweep->add_option("--out,-o", o.out, "Results folder (default: the sweep file's out)");
  sweep->add_flag("--dry-run,-n", o.dry_run, "Validate and list the cases and their overrides");
  sweep->add_flag("--force", o.force,
                  "Rerun every case from the start, completed ones included (without it completed "
                  "cases are skipped and interrupted ones continue from their newest checkpoint)");
  sweep->add_option("--case", o.case_index, "Run only case I (0-based; a Slurm array task)")
      ->check(CLI::NonNegativeNumber);
  sweep->add_flag("--collect", o.collect, "Only rebuild <out>/sweep.csv from the case folders");
  sweep->add_option("--slurm", o.slurm_path, "Write a Slurm job-array script to FILE, run nothing");
  return sweep;
}

int SweepCommand(const SweepCommandOptions& o) {
  SweepSpec spec = LoadSweepFile(o.sweep_path);
  if (!o.out.empty()) spec.out = o.out;
  const int n = int(spec.cases.size());

  if (o.collect) {
    std::vector<CaseView> views;
    for (const SweepCase& c : spec.cases) views.push_back(InspectCase(spec, c, CaseScene{}));
    return Summarise(views, WriteCsv(spec, views));
  }

  std::vector<const SweepCase*> selected;
  if (o.case_index >= 0) {
    if (o.case_index >= n) {
      throw SceneError(spec.path, 0, 0, "", "--case " + std::to_string(o.case_index) +
                                                ": the sweep has " + std::to_string(n) + " cases (0 to " +
                                                std::to_string(n - 1) + ")");
    }
    selected.push_back(&spec.cases[size_t(o.case_index)]);
  } else {
    for (const SweepCase& c : spec.cases) selected.push_back(&c);
  }
  const std::vector<CaseScene> scenes = ValidateCases(spec, selected);
  std::vector<CaseView> views;
  for (size_t i = 0; i < selected.size(); ++i) views.push_back(InspectCase(spec, *selected[i], scenes[i]));

  if (!o.slurm_path.empty()) {
    const std::string exe = ExePath();
    fs::create_directories(spec.out);  // Slurm writes the task logs there
    {
      std::ofstream out(o.slurm_path, std::ios::trunc);
      out << SlurmScript(spec, o, exe);
      if (!out) throw std::runtime_error("cannot write " + o.slurm_path);
    }
    fs::permissions(o.slurm_path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
    std::printf("sweep: %d cases validated; Slurm job array (--array=0-%d) written to %s\n", n, n - 1,
                o.slurm_path.c_str());
    std::printf("submit: jobid=$(sbatch --parsable %s); then the --collect job in its header\n",
                o.slurm_path.c_str());
    return kExitOk;
  }

  const bool completed_skip = !o.force;
  std::vector<size_t> todo;
  int skipped = 0;
  const auto plan = [&] {  // the cases to run: all with --force, else those not completed
    todo.clear();
    skipped = 0;
    for (size_t i = 0; i < views.size(); ++i) {
      if (completed_skip && views[i].status == "completed") {
        ++skipped;
      } else {
        todo.push_back(i);
      }
    }
  };
  plan();
  const int hardware = int(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = o.jobs > 0 ? o.jobs : spec.jobs > 0 ? spec.jobs : std::max(1, hardware / spec.threads_per_case);

  if (o.dry_run) {
    std::printf("sweep %s: %d cases, base scene %s, results in %s, %d thread(s) per case\n",
                spec.path.c_str(), n, spec.base.c_str(), spec.out.c_str(), spec.threads_per_case);
    for (const CaseView& v : views) {
      std::string sets;
      for (const SweepOverride& ov : v.c->overrides) sets += " --set " + ShellQuote(ov.text);
      std::printf("%3d %s [%s%s]%s\n", v.c->index, v.c->name.c_str(), v.status.c_str(),
                  completed_skip && v.status == "completed" ? ": skipped" : "", sets.c_str());
    }
    std::printf("all %d cases valid; %zu to run, %d at a time\n", int(views.size()), todo.size(), jobs);
    return kExitOk;
  }

  if (o.case_index >= 0) {  // one case (a Slurm array task): run it here, no table
    if (todo.empty()) {
      std::printf("%s already completed (--force reruns it)\n", views[0].c->name.c_str());
      return kExitOk;
    }
    const bool finished = RunCases(spec, views, todo, 1, 0, !o.force);
    if (!finished) return kExitInterrupted;
    return views[0].status == "completed" ? kExitOk : kExitFailure;
  }

  // One sweep at a time per results folder (--case tasks of a job array run side by side and
  // take no lock: each writes only its own case folder). The lock is released when the last
  // process holding it ends: the sweep and, as the descriptor is inherited (no O_CLOEXEC), its
  // running cases, so that cases left running by a killed sweep are not started twice.
  fs::create_directories(spec.out);
  const std::string lock_path = (fs::path(spec.out) / "sweep.lock").string();
  const int lock = open(lock_path.c_str(), O_WRONLY | O_CREAT, 0644);
  if (lock < 0 || flock(lock, LOCK_EX | LOCK_NB) != 0) {
    throw std::runtime_error("another surge sweep, or cases left running by one that was killed, "
                             "still run in " + spec.out + " (lock: " + lock_path + ")");
  }
  // Inspected again under the lock: a case left running by a killed sweep holds the lock until
  // it ends, and may have completed after the first inspection (it was then started twice).
  for (size_t i = 0; i < views.size(); ++i) views[i] = InspectCase(spec, *selected[i], scenes[i]);
  plan();

  std::printf("sweep %s: %d cases, %zu to run (%d completed before), %d at a time x %d thread(s); results in %s\n",
              spec.path.c_str(), n, todo.size(), skipped, jobs, spec.threads_per_case, spec.out.c_str());
  std::fflush(stdout);
  const bool finished = RunCases(spec, views, todo, jobs, skipped, !o.force);
  const int code = Summarise(views, WriteCsv(spec, views));
  return finished ? code : kExitInterrupted;
}

}  // namespace surge

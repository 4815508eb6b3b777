// `surge run`: the frame loop around Step() (DESIGN §4, §7): output cadence, progress line,
// health stop, Ctrl-C (finish the step, flush, exit non-zero).
#include "app/run.h"

#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "app/forces_command.h"
#include "core/log.h"
#include "grid/sparse_grid.h"
#include "io/checkpoint.h"
#include "io/results_writer.h"
#include "scene/scene.h"
#include "step/stages.h"
#include "step/step.h"
#include "surge/version.h"

namespace surge {
namespace {

std::atomic<bool> g_interrupted{false};

extern "C" void OnSigint(int) { g_interrupted.store(true); }

std::string UtcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

std::string FormatDuration(double s) {
  if (!(s >= 0) || s > 1e7) return "--:--";
  const long t = long(s + 0.5);
  return t >= 3600 ? fmt::format("{}:{:02}:{:02}", t / 3600, (t / 60) % 60, t % 60)
                   : fmt::format("{:02}:{:02}", t / 60, t % 60);
}

class Progress {
 public:
  // start_time: the simulated time the run starts from (a restart's checkpoint time), so that the
  // ETA extrapolates from this run's own speed.
  Progress(ProgressMode mode, Real end_time, Real start_time = 0)
      : end_time_(end_time), start_time_(start_time) {
    if (mode == ProgressMode::kAuto) mode = isatty(STDERR_FILENO) ? ProgressMode::kTerminal : ProgressMode::kPlain;
    mode_ = mode;
    start_ = last_ = Clock::now();
  }
  void Update(Real t, int64_t step, size_t particles, bool force = false) {
    if (mode_ == ProgressMode::kQuiet) return;
    const auto now = Clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    const double interval = mode_ == ProgressMode::kTerminal ? 0.25 : 10.0;
    if (!force && since < interval) return;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double steps_per_s = (step - last_step_) / std::max(since, 1e-9);
    const double updates = steps_per_s * double(particles);
    const double eta = t > start_time_ ? elapsed * (end_time_ - t) / (t - start_time_) : -1;
    const std::string line = fmt::format(
        "t = {:.4g}/{:.4g} s ({:5.1f}%)  step {}  {:.1f} steps/s  {:.2f} M particle-updates/s  "
        "elapsed {}  ETA {}",
        t, end_time_, 100.0 * t / end_time_, step, steps_per_s, updates * 1e-6,
        FormatDuration(elapsed), FormatDuration(eta));
    if (mode_ == ProgressMode::kTerminal)
      std::fprintf(stderr, "\r%s\033[K", line.c_str());
    else
      std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
    last_ = now;
    last_step_ = step;
    printed_ = true;
  }
  void Finish() {
    if (mode_ == ProgressMode::kTerminal && printed_) std::fprintf(stderr, "\n");
  }

 private:
  using Clock = std::chrono::steady_clock;
  ProgressMode mode_;
  Real end_time_;
  Real start_time_;
  Clock::time_point start_, last_;
  int64_t last_step_ = 0;
  bool printed_ = false;
};

// The dynamic obstacles' names in State::rigid order (ObstacleMotion::body).
std::vector<std::string> RigidBodyNames(const Model& model) {
  std::vector<std::string> names;
  for (const Obstacle& ob : model.obstacles) {
    if (ob.motion.kind != ObstacleMotionKind::kDynamic) continue;
    const size_t body = size_t(ob.motion.body);
    if (names.size() <= body) names.resize(body + 1);
    names[body] = ob.name;
  }
  return names;
}

// <out>/summary.json: the force analysis of the finished result, the same document as
// `surge forces --json` (docs/results-format.md, "summary.json"); written through a temporary
// file and a rename, so a reader never sees half of it. A failure is a warning, not a failed run.
void WriteSummaryJson(const std::string& out_dir, RunSummary& summary) {
  const std::string path = out_dir + "/summary.json";
  try {
    ForcesCommandOptions options;
    options.result_path = summary.h5_path;
    const std::string json = ForcesSummaryJson(options, &summary.analysis_lines);
    const std::string tmp = path + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw std::runtime_error("cannot create " + tmp);
    const bool ok = std::fwrite(json.data(), 1, json.size(), f) == json.size();
    if (std::fclose(f) != 0 || !ok) throw std::runtime_error("cannot write " + tmp);
    std::filesystem::rename(tmp, path);
    summary.summary_json_path = path;
  } catch (const std::exception& e) {
    LogWarn(std::string("summary.json not written: ") + e.what());
  }
}

// The checkpoints of the run in `out_dir` whose file names sort after `after` (later steps),
// or all of them when `after` is "", and every half-written one (<name>_step_*.h5.tmp, left by a
// kill during a write: WriteCheckpoint renames a file only once it is complete).
void RemoveCheckpoints(const std::string& out_dir, const std::string& name,
                       const std::string& after) {
  for (const std::string& path : ListCheckpoints(out_dir, name)) {
    if (!after.empty() && std::filesystem::path(path).filename().string() <= after) continue;
    std::error_code ec;
    std::filesystem::remove(path, ec);
    Log(LogLevel::kDebug, "removed checkpoint " + path);
  }
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::path(out_dir) / "checkpoints";
  if (!std::filesystem::is_directory(dir, ec)) return;
  const std::string prefix = name + "_step_", suffix = ".h5.tmp";
  std::vector<std::filesystem::path> stale;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string f = e.path().filename().string();
    if (f.size() > prefix.size() + suffix.size() && f.rfind(prefix, 0) == 0 &&
        f.compare(f.size() - suffix.size(), suffix.size(), suffix) == 0)
      stale.push_back(e.path());
  }
  for (const auto& path : stale) {
    std::filesystem::remove(path, ec);
    LogInfo("removed the half-written checkpoint " + path.string());
  }
}

// <out>/checkpoints/<name>_failed_step_<step, 9 digits>.h5: the diagnostic checkpoint a health
// stop writes (the state of the failed step, docs/stability.md). ListCheckpoints does not list it,
// so it is never rotated away nor offered for --restart.
std::string FailedCheckpointPath(const std::string& out_dir, const std::string& name, int64_t step) {
  return fmt::format("{}/checkpoints/{}_failed_step_{:09}.h5", out_dir, name, step);
}

bool IsFailedCheckpoint(const std::string& path) {
  return std::filesystem::path(path).filename().string().find("_failed_step_") != std::string::npos;
}

// Refuses a new run over an existing result unless options.force, and clears the old result's
// checkpoints (they would continue a run that is being overwritten).
void PrepareNewRun(const Model& model, const RunOptions& options) {
  CheckNewRunAllowed(options.out_dir, model.name, options.force);
  std::error_code ec;
  RemoveCheckpoints(options.out_dir, model.name, "");
  // and the old result's diagnostic checkpoint of a failed step, if any
  const std::filesystem::path dir = std::filesystem::path(options.out_dir) / "checkpoints";
  const std::string prefix = model.name + "_failed_step_";
  if (std::filesystem::is_directory(dir, ec)) {
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
      if (e.path().filename().string().rfind(prefix, 0) == 0) std::filesystem::remove(e.path(), ec);
    }
  }
}

// Reads options.restart and checks that it was written from this scene with these overrides.
Checkpoint ReadMatchingCheckpoint(const LoadedScene& scene, const RunOptions& options) {
  if (IsFailedCheckpoint(options.restart)) {
    throw RunRefused("'" + options.restart + "' is the diagnostic checkpoint of a failed step (the "
                     "state that failed the health check), not a state to continue from; restart "
                     "from a periodic checkpoint (<name>_step_<step>.h5) or run again with the "
                     "remedy the stop message names");
  }
  Checkpoint c;
  try {
    c = ReadCheckpoint(options.restart);
  } catch (const IoError& e) {
    throw RunRefused(std::string("cannot restart: ") + e.what());
  }
  const std::string hash = SceneHash(scene.text);
  if (c.scene_hash != hash) {
    throw RunRefused("checkpoint '" + options.restart + "' was written from another scene ('" +
                     c.scene_path + "', hash " + c.scene_hash + ") than '" + scene.path +
                     "' (hash " + hash + "); restart with the scene file it was written from");
  }
  if (c.resolved_hash != SceneHash(scene.resolved_yaml)) {
    // A mesh file whose content changed (its hash is part of the resolved scene) is named first.
    const auto then = MeshFileHashes(c.resolved_yaml), now = MeshFileHashes(scene.resolved_yaml);
    for (size_t i = 0; i < std::min(then.size(), now.size()); ++i) {
      if (then[i].first == now[i].first && then[i].second != now[i].second) {
        throw RunRefused("mesh file '" + now[i].first + "' changed since checkpoint '" +
                         options.restart + "' was written (content hash " + then[i].second +
                         ", now " + now[i].second +
                         "); restart with the mesh files of the interrupted run");
      }
    }
    throw RunRefused("checkpoint '" + options.restart + "' was written from '" + scene.path +
                     "' with other --set overrides (resolved scene hash " + c.resolved_hash +
                     ", now " + SceneHash(scene.resolved_yaml) +
                     "); restart with the same --set options as the interrupted run");
  }
  if (c.name != scene.model.name) {
    throw RunRefused("checkpoint '" + options.restart + "' belongs to the run '" + c.name +
                     "', not '" + scene.model.name + "'");
  }
  return c;
}

}  // namespace

void CheckNewRunAllowed(const std::string& out_dir, const std::string& name, bool force) {
  const std::string h5 = (std::filesystem::path(out_dir) / (name + ".h5")).string();
  std::error_code ec;
  if (force || !std::filesystem::exists(h5, ec)) return;
  const std::vector<std::string> checkpoints = ListCheckpoints(out_dir, name);
  throw RunRefused("'" + h5 + "' exists: pass --force to overwrite it" +
                   (checkpoints.empty() ? std::string(", or --out to write elsewhere")
                                        : ", --out to write elsewhere, or --restart " +
                                              checkpoints.back() + " to continue it"));
}

RunSummary RunScene(LoadedScene& scene, const RunOptions& options) {
  const Model& model = scene.model;
  State& state = scene.state;
  const int threads = options.threads > 0 ? options.threads
                                          : int(std::max(1u, std::thread::hardware_concurrency()));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);

  const bool restart = !options.restart.empty();
  Checkpoint resume;
  if (restart) {
    const ParticleLayout needed = state.particles.layout;
    state = State{};  // the seeded particles go before the checkpoint's arrive (peak memory)
    resume = ReadMatchingCheckpoint(scene, options);
    const ParticleLayout& held = resume.state.particles.layout;
    const auto missing = [&](bool need, bool have, const char* array) {
      if (need && !have)
        throw RunRefused("checkpoint '" + options.restart + "' has no particles/" + array +
                         " array, which this scene's materials or tractions need");
    };
    missing(needed.affine, held.affine, "C");
    missing(needed.strain, held.strain, "strain");
    missing(needed.elastic_b, held.elastic_b, "elastic_b");
    missing(needed.history, held.history, "history");
    missing(needed.ext_force, held.ext_force, "ext_force");
    if (needed.history && held.history_slots < needed.history_slots) {
      throw RunRefused("checkpoint '" + options.restart + "' has " +
                       std::to_string(held.history_slots) + " history slots per particle, " +
                       "fewer than the " + std::to_string(needed.history_slots) +
                       " this scene's materials use");
    }
    state = std::move(resume.state);
    resume.state = State{};
  } else {
    PrepareNewRun(model, options);
  }

  RunMetadata meta;
  meta.scene_path = scene.path;
  meta.scene_text = scene.text;
  meta.resolved_yaml = scene.resolved_yaml;
  meta.version = SURGE_VERSION;
  meta.git_hash = SURGE_GIT_HASH;
  meta.command_line = options.command_line;
  meta.start_time_utc = UtcNow();
  meta.threads = threads;
  // A restart reopens the result and cuts it back to the checkpoint (ResultsWriter).
  std::unique_ptr<ResultsWriter> writer_owner =
      restart ? std::make_unique<ResultsWriter>(options.out_dir, model.name, model, resume.result)
              : std::make_unique<ResultsWriter>(options.out_dir, model.name, meta, model);
  ResultsWriter& writer = *writer_owner;

  RunSummary summary;
  const Pipeline pipeline = MakePipeline(model);
  Workspace work;
  for (const RigidBodyState& b : resume.bullet)
    work.rigid_restart.push_back({b.position, b.rotation, b.velocity, b.angular_velocity});
  work.rigid_restart_contacts = std::move(resume.bullet_contacts);
  if (restart) {  // what the last step handed to the next one (io/checkpoint.h)
    work.bulk_viscosity.q = std::move(resume.bulk_viscosity_q);
    work.bulk_viscosity.id = std::move(resume.bulk_viscosity_id);
    work.bulk_viscosity.dt_bound = resume.bulk_viscosity_dt_bound;
  }
  StepReport report;
  Progress progress(options.progress, model.time.end, state.time);

  g_interrupted.store(false);
  // Ctrl-C, and SIGTERM (what a batch scheduler such as Slurm sends at the time limit), both
  // finish the step, write a checkpoint and flush the results.
  auto previous = std::signal(SIGINT, OnSigint);
  auto previous_term = std::signal(SIGTERM, OnSigint);

  auto write_snapshot = [&]() {
    writer.WriteSnapshot(state);
    if (model.output.vdb && work.grid.block_count() > 0) {
      const std::string path = fmt::format("{}/{}_grid_{:06}.vdb", options.out_dir, model.name,
                                           writer.snapshot_count() - 1);
      ExportGridVdb(work.grid, model.dx, path);
    }
  };

  // The state at t = 0 (a restart has it in the result already).
  if (model.output.energy && !restart) writer.AppendEnergy(ComputeEnergy(model, state));
  // Reaction forces on the domain walls and every obstacle, logged every step (DESIGN §7).
  const std::vector<ForceChannel> channels = ForceChannels(model);
  if (!channels.empty()) writer.BeginForces(channels);
  // Pose and velocities of every dynamic obstacle, logged every step.
  const bool rigid = !state.rigid.empty();
  if (rigid) writer.BeginRigid(RigidBodyNames(model));
  ContactReport forces;
  if (!restart) write_snapshot();
  Real next_output = model.output.every > 0 ? model.output.every : model.time.end;
  // Periodic checkpoints every output.checkpoint_every of simulated time (0: none).
  const Real checkpoint_every = model.output.checkpoint_every;
  Real next_checkpoint = checkpoint_every > 0 ? checkpoint_every : 0;
  if (restart) {
    next_output = resume.next_output;
    next_checkpoint = resume.next_checkpoint;
    // Checkpoints after this one belong to the part of the run that is being redone.
    RemoveCheckpoints(options.out_dir, model.name,
                      std::filesystem::path(CheckpointPath(options.out_dir, model.name, state.step))
                          .filename()
                          .string());
    LogInfo(fmt::format("continuing from {} at t = {:.6g} s, step {}", options.restart,
                        state.time, state.step));
  }
  // Writes a checkpoint of the state after the last completed step (docs/results-format.md,
  // "Checkpoints") and keeps the newest output.checkpoints_keep. A failure is a warning: the
  // run and its results go on.
  // diagnostic: the failed state of a health stop (FailedCheckpointPath; not rotated).
  auto write_checkpoint = [&](bool diagnostic = false) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string path = diagnostic ? FailedCheckpointPath(options.out_dir, model.name, state.step)
                                        : CheckpointPath(options.out_dir, model.name, state.step);
    Checkpoint c;
    c.result = writer.Flush();
    c.next_output = next_output;
    c.next_checkpoint = next_checkpoint;
    c.name = model.name;
    c.scene_path = scene.path;
    c.scene_text = scene.text;
    c.resolved_yaml = scene.resolved_yaml;
    c.version = SURGE_VERSION;
    c.git_hash = SURGE_GIT_HASH;
    if (work.rigid_world) {
      for (const int h : work.rigid_handle) {
        const RigidWorld::BodyState b = work.rigid_world->State(h);
        c.bullet.push_back({b.position, b.rotation, b.velocity, b.angular_velocity});
      }
      c.bullet_contacts = work.rigid_world->ContactCache();
    }
    c.bulk_viscosity_q = work.bulk_viscosity.q;
    c.bulk_viscosity_id = work.bulk_viscosity.id;
    c.bulk_viscosity_dt_bound = work.bulk_viscosity.dt_bound;
    c.state = std::move(state);  // written in place: no copy of the particles
    try {
      WriteCheckpoint(path, c);
    } catch (const std::exception& e) {
      state = std::move(c.state);
      LogWarn(std::string("checkpoint not written: ") + e.what());
      return;
    }
    state = std::move(c.state);
    const std::vector<std::string> all =
        diagnostic ? std::vector<std::string>{} : ListCheckpoints(options.out_dir, model.name);
    for (size_t k = 0; k + size_t(model.output.checkpoints_keep) < all.size(); ++k) {
      std::error_code ec;
      std::filesystem::remove(all[k], ec);
    }
    std::error_code ec;
    const double mb = double(std::filesystem::file_size(path, ec)) / 1e6;
    LogInfo(fmt::format("{} {} ({:.1f} MB, {:.2f} s)",
                        diagnostic ? "diagnostic checkpoint of the failed step (for inspection, "
                                     "not for --restart):"
                                   : "checkpoint",
                        path, ec ? 0.0 : mb,
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
  };
  const auto start = std::chrono::steady_clock::now();
  double particle_steps = 0;
  const Real end_tolerance = 1e-12 * model.time.end;
  bool unhealthy = false;
  summary.exit_status = "completed";
  while (state.time < model.time.end - end_tolerance) {
    const size_t n = state.particles.size();
    Step(model, pipeline, state, work, report);
    if (report.health.status != HealthStatus::kOk) {
      // Health stop (docs/stability.md): the message names the step, the stage, the field, the
      // particle and the likely cause; the failed state goes to a diagnostic checkpoint, and the
      // results keep only the healthy snapshots and series (no final snapshot of the failed state).
      unhealthy = true;
      const Health& h = report.health;
      summary.exit_code = kExitUnhealthy;
      summary.exit_status = "stopped at t = " + fmt::format("{:.6g}", state.time) + " s, step " +
                            std::to_string(state.step) +
                            (h.stage.empty() ? "" : ", stage " + h.stage) +
                            (h.field.empty() ? "" : ", field " + h.field) + ": " + h.detail;
      LogError(summary.exit_status);
      write_checkpoint(/*diagnostic=*/true);
      const std::vector<std::string> good = ListCheckpoints(options.out_dir, model.name);
      if (!good.empty()) LogInfo("last periodic checkpoint (a healthy state): " + good.back());
      break;
    }
    particle_steps += double(n);
    if (model.output.energy) writer.AppendEnergy(report.energy);
    if (!channels.empty()) {
      CollectForces(model, report, forces);
      writer.AppendForces(state.time, state.step, state.dt, forces);
    }
    if (rigid) writer.AppendRigid(state.time, state.step, state.rigid);
    if (report.damping_released) {
      LogInfo(fmt::format("static equilibrium at t = {:.6g} s (force ratio {:.3g}, energy ratio "
                          "{:.3g}; Anura3D (6.29)-(6.30)): local damping off from the next step",
                          state.time, report.force_ratio, report.energy_ratio));
    }
    if (report.removed_last_step > 0)
      Log(LogLevel::kDebug, fmt::format("{} particles left the domain", report.removed_last_step));
    const bool done = state.time >= model.time.end - end_tolerance;
    if (state.time >= next_output - end_tolerance && !done) {
      write_snapshot();
      while (next_output <= state.time + end_tolerance) next_output += model.output.every;
    }
    const bool interrupted =
        g_interrupted.load() || (options.stop_at_step >= 0 && state.step >= options.stop_at_step);
    if (checkpoint_every > 0 && state.time >= next_checkpoint - end_tolerance && !done) {
      while (next_checkpoint <= state.time + end_tolerance) next_checkpoint += checkpoint_every;
      if (!interrupted) write_checkpoint();
    }
    progress.Update(state.time, state.step, state.particles.size());
    if (interrupted) {
      summary.exit_code = kExitInterrupted;
      summary.exit_status = "interrupted at t = " + fmt::format("{:.6g}", state.time) + " s";
      LogWarn("interrupted: finishing the current step, writing a checkpoint and flushing the results");
      if (!done) write_checkpoint();
      break;
    }
  }
  progress.Update(state.time, state.step, state.particles.size(), /*force=*/true);
  progress.Finish();
  std::signal(SIGINT, previous);
  std::signal(SIGTERM, previous_term);
  if (!unhealthy) write_snapshot();
  summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.steps = state.step;
  summary.end_time = state.time;
  summary.particle_updates_per_second = particle_steps / std::max(summary.wall_seconds, 1e-9);
  summary.force_channels = channels;
  if (!channels.empty()) {
    const ForceSummary& fs = writer.force_summary();
    for (size_t k = 0; k < fs.size(); ++k) summary.force_peaks.push_back(fs.structure(k));
  }
  writer.Close(report.stage_seconds, state.step, summary.wall_seconds, summary.exit_status);
  summary.h5_path = writer.h5_path();
  summary.xmf_path = writer.xmf_path();
  summary.snapshots = writer.snapshot_count();
  WriteSummaryJson(options.out_dir, summary);
  return summary;
}

void PrintSummary(const LoadedScene& scene, const RunSummary& s) {
  const Model& model = scene.model;
  std::printf("\n== %s: %s\n", model.name.c_str(), s.exit_status.c_str());
  std::printf("   simulated %.6g s in %lld steps, wall %.2f s, %.3g particle-updates/s\n",
              s.end_time, static_cast<long long>(s.steps), s.wall_seconds,
              s.particle_updates_per_second);
  std::printf("   particles %zu (removed through open sides: %lld)\n", scene.state.particles.size(),
              static_cast<long long>(scene.state.particles_removed));
  // Force summary: peak |F| (every step counted, seed spec §5.4) and impulse per structure and
  // per face with any load.
  if (!s.force_channels.empty()) std::printf("   reaction forces on the structures (every step; 2-D: per m):\n");
  for (size_t k = 0; k < s.force_channels.size() && k < s.force_peaks.size(); ++k) {
    const StructurePeak& p = s.force_peaks[k];
    const auto print = [](const std::string& label, const ForcePeak& f) {
      std::printf("     %-22s peak |F| %12.5g N at t = %-9.4g F = (%.4g, %.4g, %.4g) N, impulse (%.4g, %.4g, %.4g) N s\n",
                  label.c_str(), f.peak_force, std::isnan(f.peak_time) ? 0.0 : f.peak_time,
                  f.force_at_peak.x(), f.force_at_peak.y(), f.force_at_peak.z(), f.impulse.x(),
                  f.impulse.y(), f.impulse.z());
    };
    print(s.force_channels[k].name, p);
    for (size_t f = 0; f < p.faces.size(); ++f) {
      if (p.faces[f].peak_force > 0) print("  " + s.force_channels[k].faces[f], p.faces[f]);
    }
  }
  // Final state of every dynamic body (its reference point; the series are in rigid_<name>.csv).
  const std::vector<std::string> bodies = RigidBodyNames(model);
  if (!scene.state.rigid.empty()) std::printf("   dynamic bodies at the end:\n");
  for (size_t b = 0; b < scene.state.rigid.size() && b < bodies.size(); ++b) {
    const RigidBodyState& r = scene.state.rigid[b];
    std::printf("     %-22s position (%.5g, %.5g, %.5g) m, speed %.4g m/s, angular speed %.4g rad/s\n",
                bodies[b].c_str(), r.position.x(), r.position.y(), r.position.z(),
                r.velocity.norm(), r.angular_velocity.norm());
  }
  for (const std::string& line : s.analysis_lines) std::printf("   %s\n", line.c_str());
  std::printf("   results: %s (%d snapshots)\n            %s (open in ParaView)\n",
              s.h5_path.c_str(), s.snapshots, s.xmf_path.c_str());
  if (!s.summary_json_path.empty())
    std::printf("            %s (surge forces --json)\n", s.summary_json_path.c_str());
}

}  // namespace surge

// Checkpoints of a run (issue #9, `surge run --restart`): one HDF5 file per checkpoint,
// <out>/checkpoints/<name>_step_<step>.h5, holding the whole State (STYLE H.4) and what the frame
// loop and the results writer need to continue bitwise: the next output and checkpoint times, the
// rows of every series and the running force summaries (ResultPosition), Bullet's own state of
// every dynamic body, and the scene verbatim with its hash. Layout: docs/results-format.md,
// "Checkpoints". HDF5 stays in checkpoint.cpp.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/state.h"
#include "io/results_writer.h"

namespace surge {

struct Checkpoint {
  State state;
  // Bullet's own state of each dynamic body (centre of mass, principal frame; RigidWorld::State),
  // by ObstacleMotion::body: restored as it was, not re-derived from State::rigid, so that the
  // continued Bullet world starts bitwise where the interrupted one stood. Empty when the run
  // had no Bullet world yet.
  std::vector<RigidBodyState> bullet;
  // Bullet's contact manifolds (RigidWorld::ContactCache): restored with the bodies, so that a
  // restart during a contact continues bitwise. Empty without a Bullet world.
  std::vector<uint8_t> bullet_contacts;
  // Workspace values a step hands to the next (everything else in Workspace is rebuilt each
  // step): the artificial bulk viscosity q_p of the last step with the particle ids it belongs to,
  // and its time-step bound (stabilize/bulk_viscosity.h). Empty / 1e300 without bulk viscosity.
  std::vector<Real> bulk_viscosity_q;          // [Pa]
  std::vector<int64_t> bulk_viscosity_id;
  Real bulk_viscosity_dt_bound = 1e300;        // [s]
  Real next_output = 0;      // time of the next periodic snapshot [s]
  Real next_checkpoint = 0;  // time of the next periodic checkpoint [s] (0: none)
  ResultPosition result;     // the result's series as they stood (ResultsWriter::Flush)
  std::string name;          // the scene's name (the result's file name)
  std::string scene_path;    // the scene file as given to `surge run`
  std::string scene_text;    // the scene file verbatim
  std::string resolved_yaml; // the scene after --set, defaults filled in
  std::string scene_hash;    // SceneHash(scene_text); filled by ReadCheckpoint
  std::string resolved_hash; // SceneHash(resolved_yaml); filled by ReadCheckpoint
  std::string version, git_hash;  // of the surge that wrote it
};

// FNV-1a (64 bit) of `text`, 16 hex digits.
std::string SceneHash(const std::string& text);

// <out_dir>/checkpoints/<name>_step_<step, 9 digits>.h5
std::string CheckpointPath(const std::string& out_dir, const std::string& name, int64_t step);

// The checkpoints of `name` in <out_dir>/checkpoints, oldest (lowest step) first.
std::vector<std::string> ListCheckpoints(const std::string& out_dir, const std::string& name);

// Writes `c` to `path` through `path`.tmp and a rename, so that a file under the final name is
// always whole; creates the folder. Throws IoError naming the file on failure.
void WriteCheckpoint(const std::string& path, const Checkpoint& c);

// Reads a checkpoint. Throws IoError naming the file when it is missing, damaged (its bytes do
// not match the checksum written with it, checked before HDF5 opens it), not HDF5, not a Surge
// checkpoint, of another format version, or inconsistent (array lengths). `verify_checksum`
// false skips the checksum (tests/fuzz/fuzz_io.cpp, which fuzzes what lies behind it).
Checkpoint ReadCheckpoint(const std::string& path, bool verify_checksum = true);

}  // namespace surge

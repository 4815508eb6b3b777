// Results of one run (DESIGN §7): <out>/<name>.h5 with run metadata, particle snapshots, the
// energy series, the per-step force series (/forces, and <out>/forces_<structure>.csv) and the
// per-step motion of the dynamic rigid bodies (/rigid, and <out>/rigid_<body>.csv), plus
// <out>/<name>.xmf so ParaView opens the HDF5 directly. HDF5 stays in hdf5_writer.cpp (pimpl).
// Layout: docs/results-format.md.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/contact_report.h"
#include "contact/force_summary.h"
#include "core/model.h"
#include "core/stage.h"
#include "core/state.h"
#include "core/step_report.h"

namespace surge {

struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct RunMetadata {
  std::string scene_path;
  std::string scene_text;     // the scene file verbatim
  std::string resolved_yaml;  // the parsed scene with defaults filled in
  std::string version;
  std::string git_hash;
  std::string command_line;
  std::string start_time_utc;
  int threads = 1;
};

// Where a result stood when a checkpoint was taken (io/checkpoint.h, ResultsWriter::Flush): what
// a restart truncates the result to before it continues.
struct ResultPosition {
  int snapshots = 0;        // snapshot groups /snapshots/000000 ... kept
  int64_t energy_rows = 0;  // rows of every /energy column
  int64_t force_rows = 0;   // rows of every /forces series and of every forces_<name>.csv
  int64_t rigid_rows = 0;   // rows of every /rigid series and of every rigid_<name>.csv
  std::vector<StructurePeak> force_peaks;  // ForceSummary::structure(s) for every channel
  int64_t force_samples = 0;               // ForceSummary::samples()
};

class ResultsWriter {
 public:
  // Creates out_dir if needed and the .h5 file (truncating an old one). Throws IoError naming
  // the path on failure, and for a name outside [A-Za-z0-9_-]+ (results stay inside out_dir).
  ResultsWriter(const std::string& out_dir, const std::string& name, const RunMetadata& meta,
                const Model& model);
  // Reopens the result <out_dir>/<name>.h5 of an interrupted run to continue it from a checkpoint
  // (`surge run --restart`): snapshots from `resume.snapshots` on, the /energy rows from
  // `resume.energy_rows` on and /timing are removed, and the .xmf is rewritten for the snapshots
  // kept; BeginForces and BeginRigid then truncate the force and rigid series (HDF5 and CSV) to
  // the checkpoint's rows and continue its force summary instead of starting new ones. Throws
  // IoError naming the file when it is missing, not a Surge result, or shorter than the checkpoint.
  ResultsWriter(const std::string& out_dir, const std::string& name, const Model& model,
                const ResultPosition& resume);
  ~ResultsWriter();  // closes the file if Close was not called; never throws
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  // One particle snapshot; flushes the .h5 (a killed run keeps every completed snapshot and the
  // energy rows up to it) and rewrites the .xmf atomically.
  void WriteSnapshot(const State& state);
  // Buffered; written at each snapshot and on Close.
  void AppendEnergy(const EnergyRecord& e);
  // Starts the force series: creates /forces/<name>/... in the .h5 and truncates and heads
  // <out>/forces_<name>.csv for every channel. Call once, before the first AppendForces; may be
  // skipped when there are no channels. Throws IoError for a second call, a structure name
  // outside [A-Za-z0-9_-]+, a face name outside [A-Za-z0-9_+-]+, a repeated name, and when a CSV
  // file cannot be created.
  void BeginForces(const std::vector<ForceChannel>& channels);
  // One row per structure: the forces of the step of length dt [s] that ended at `time` [s]
  // (state.time and state.dt after Step). Buffered; the rows reach the .h5 and the CSV files
  // (each flushed) at each WriteSnapshot, whenever 1000 rows are pending, and on Close; the
  // peak/impulse summary (ForceSummary) is updated at once and written on Close.
  // Pre: BeginForces was called; report has the channels' shape (else std::logic_error).
  void AppendForces(Real time, int64_t step, Real dt, const ContactReport& report);
  // Starts the rigid-body series: creates /rigid/<name>/... in the .h5 and truncates and heads
  // <out>/rigid_<name>.csv for every dynamic body, names in State::rigid order
  // (ObstacleMotion::body). Call once, before the first AppendRigid; may be skipped when there
  // are no dynamic bodies. Throws IoError for a second call, a name outside [A-Za-z0-9_-]+, a
  // repeated name, and when a CSV file cannot be created.
  void BeginRigid(const std::vector<std::string>& names);
  // One row per body: its state at `time` [s] after `step` completed steps (state.time,
  // state.step and state.rigid after Step); the rotation is stored as a unit quaternion
  // (RotationQuaternion). Buffered and flushed like the force rows (at each WriteSnapshot,
  // whenever 1000 rows are pending, and on Close).
  // Pre: BeginRigid was called with bodies.size() names (else std::logic_error).
  void AppendRigid(Real time, int64_t step, const std::vector<RigidBodyState>& bodies);
  // Writes every pending row (HDF5, flushed, and the CSV files) and returns where the result
  // stands now: what a checkpoint taken at this moment records.
  ResultPosition Flush();
  // Writes the pending rows, the force summary, stage timings and the exit status, then closes
  // the files.
  void Close(const StageSeconds& stage_seconds, int64_t steps, double wall_seconds,
             const std::string& exit_status);

  std::string h5_path() const;
  std::string xmf_path() const;
  int snapshot_count() const;
  // <out>/forces_<structure>.csv (whether or not it exists).
  std::string forces_csv_path(const std::string& structure) const;
  // <out>/rigid_<body>.csv (whether or not it exists).
  std::string rigid_csv_path(const std::string& body) const;
  // Peaks and impulses of every row appended so far (empty before BeginForces).
  const ForceSummary& force_summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Strain invariants of a deformation gradient (Hencky strain eps = 1/2 ln(F F^T)):
// volumetric ln J and equivalent deviatoric strain sqrt(2/3 e:e), e = dev(eps).
void StrainInvariants(const Mat3& F, Real& volumetric, Real& equivalent);

// The unit quaternion (w, x, y, z) of a rotation matrix R (R = the rotation of q, Hamilton
// convention, as Eigen::Quaterniond::toRotationMatrix), with w >= 0 (q and -q are the same
// rotation; this picks one so that every row can be read on its own, at the cost of a sign jump
// where a body turns through 180 degrees). Eigen's conversion (K. Shoemake, "Quaternion Calculus
// and Fast Animation", SIGGRAPH 1987 course notes: from the trace, or from the largest diagonal
// element when the trace is <= 0), then normalised.
std::array<Real, 4> RotationQuaternion(const Mat3& R);

// HDF5 library version, e.g. "1.10.8" (for `surge info`).
std::string Hdf5Version();

}  // namespace surge

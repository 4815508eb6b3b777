// Results of one run (DESIGN §7): <out>/<name>.h5 with run metadata, particle snapshots and the
// energy series, plus <out>/<name>.xmf so ParaView opens the HDF5 directly. HDF5 stays in
// hdf5_writer.cpp (pimpl). Layout: docs/results-format.md.
#pragma once
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

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

class ResultsWriter {
 public:
  // Creates out_dir if needed and the .h5 file (truncating an old one). Throws IoError naming
  // the path on failure.
  ResultsWriter(const std::string& out_dir, const std::string& name, const RunMetadata& meta,
                const Model& model);
  ~ResultsWriter();  // closes the file if Close was not called; never throws
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;

  // One particle snapshot; flushes the .h5 (a killed run keeps every completed snapshot and the
  // energy rows up to it) and rewrites the .xmf atomically.
  void WriteSnapshot(const State& state);
  // Buffered; written at each snapshot and on Close.
  void AppendEnergy(const EnergyRecord& e);
  // Writes stage timings and the exit status, then closes the file.
  void Close(const StageSeconds& stage_seconds, int64_t steps, double wall_seconds,
             const std::string& exit_status);

  std::string h5_path() const;
  std::string xmf_path() const;
  int snapshot_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Strain invariants of a deformation gradient (Hencky strain eps = 1/2 ln(F F^T)):
// volumetric ln J and equivalent deviatoric strain sqrt(2/3 e:e), e = dev(eps).
void StrainInvariants(const Mat3& F, Real& volumetric, Real& equivalent);

// HDF5 library version, e.g. "1.10.8" (for `surge info`).
std::string Hdf5Version();

}  // namespace surge

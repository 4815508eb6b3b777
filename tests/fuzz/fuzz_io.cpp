// Fuzz target: the HDF5 readers of src/io, on arbitrary bytes as the file: byte 0 picks the
// reader (by byte % 3): ReadCheckpoint (`surge run --restart`), ReadResultForces (`surge
// forces`), ReadResultStatus (`surge sweep`); the rest is the file. Contract checked: a file that
// cannot be used is rejected with an IoError naming it (ReadResultStatus never throws); any other
// exception, a crash, a hang or a sanitizer report in our code is a finding. The HDF5 library
// itself is not instrumented (a crash inside it still shows, with its stack).
#include <cstdint>
#include <string>

#include "fuzz/fuzz_util.h"
#include "io/checkpoint.h"
#include "io/result_status.h"
#include "io/results_reader.h"

// libFuzzer runs (coverage-guided, long) read checkpoints without the checksum check, which would
// refuse nearly every mutated file before HDF5 and the reader behind it see it; they then also
// reach libhdf5's own hangs and over-reads on corrupt files (docs/robustness.md, third-party
// findings), which production never does. The replay and mutation runs of every build (CI)
// check what `surge run --restart` does: the checksum first.
#ifdef SURGE_LIBFUZZER
constexpr bool kVerifyChecksum = false;
#else
constexpr bool kVerifyChecksum = true;
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int reader = data[0] % 3;
  const std::string path = surge::fuzz::ScratchPath("io", ".h5");
  surge::fuzz::WriteFile(path, data + 1, size - 1);
  try {
    if (reader == 0) {
      const surge::Checkpoint c = surge::ReadCheckpoint(path, kVerifyChecksum);
      // What --restart relies on: every array as long as the positions, groups inside them.
      const size_t n = c.state.particles.size();
      const surge::Particles& P = c.state.particles;
      if (P.v.size() != n || P.F.size() != n || P.history.size() != n || P.id.size() != n ||
          P.material.size() != n || P.body.size() != n || P.mass.size() != n)
        surge::fuzz::Finding("checkpoint arrays of different lengths were accepted");
      if (c.bulk_viscosity_q.size() != c.bulk_viscosity_id.size())
        surge::fuzz::Finding("bulk viscosity arrays of different lengths were accepted");
    } else if (reader == 1) {
      const surge::StoredResult r = surge::ReadResultForces(path);
      for (const surge::StoredForceSeries& s : r.structures) {
        const size_t n = s.time.size();
        if (s.dt.size() != n || s.force.size() != n)
          surge::fuzz::Finding("force series of different lengths were accepted");
      }
    } else {
      (void)surge::ReadResultStatus(path);
    }
  } catch (const surge::IoError& e) {
    if (std::string(e.what()).find(path) == std::string::npos)
      surge::fuzz::Finding(std::string("IoError without the file name: ") + e.what());
  } catch (const std::exception& e) {
    surge::fuzz::Finding(std::string("not an IoError: ") + e.what());
  }
  return 0;
}

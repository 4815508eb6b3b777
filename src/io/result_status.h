// How a run ended, read back from its results file (/timing, docs/results-format.md). Used by
// `surge sweep` to tell finished cases from unfinished ones. HDF5 stays in result_status.cpp.
#pragma once
#include <cstdint>
#include <string>

namespace surge {

struct ResultStatus {
  bool readable = false;    // the file exists and HDF5 opened it
  bool closed = false;      // /timing exists: the run closed the file (completed or stopped)
  std::string exit_status;  // /timing exit_status: "completed", "interrupted" or a diagnostic
  int64_t steps = 0;        // /timing steps
  double wall_seconds = 0;  // /timing wall_seconds [s]
};

// Reads /timing of `h5_path`. Never throws: a missing, unreadable or still open (crashed) file
// gives readable = false or closed = false.
ResultStatus ReadResultStatus(const std::string& h5_path);

}  // namespace surge

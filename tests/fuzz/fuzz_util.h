// Shared pieces of the fuzz targets (tests/fuzz, docs/robustness.md "Fuzzing"): a scratch file
// per process for the readers that take a path, and the one way a target reports a finding.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

namespace surge::fuzz {

// A finding that is not a crash (an exception of the wrong type, a message without the file):
// printed and aborted, so that libFuzzer saves the input and the replay test fails.
[[noreturn]] inline void Finding(const std::string& what) {
  std::fprintf(stderr, "FUZZ FINDING: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// <dir>/surge_fuzz_<pid>_<tag><ext>: /dev/shm when there is one (no disk writes per input),
// else $TMPDIR or /tmp. One file per process and tag, rewritten for every input.
inline std::string ScratchPath(const std::string& tag, const std::string& ext) {
  std::string dir = "/dev/shm";
  if (access(dir.c_str(), W_OK) != 0) {
    const char* t = std::getenv("TMPDIR");
    dir = t ? t : "/tmp";
  }
  return dir + "/surge_fuzz_" + std::to_string(getpid()) + "_" + tag + ext;
}

inline void WriteFile(const std::string& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  if (!out) Finding("cannot write the scratch file " + path);
}

}  // namespace surge::fuzz

// Driver for builds without libFuzzer (GCC, the default build and CI). Two modes:
//
// Replay (default): runs LLVMFuzzerTestOneInput once on every file named on the command line or
// found (recursively, sorted) in a folder named there. Arguments starting with '-' (libFuzzer
// flags such as -runs=0) are ignored, so ctest runs the same command line in both builds.
//
// Mutation (-mutate_seconds=S, optional -seed=N, default 1): after the replay, feeds mutants of
// the corpus files for S seconds: each a corpus file (or a splice of two) with 1-8 random edits
// (bit flips, random or "interesting" bytes, inserted, erased or duplicated ranges, numbers
// rewritten as other numbers), from a PRNG seeded with N, so the sequence is the same on every
// machine. No coverage guidance (that needs libFuzzer and clang: docs/robustness.md), but it runs
// in CI on every change. Each mutant is written to $TMPDIR (or /tmp)/surge_fuzz_last_<target>_<pid>
// before it runs, so after a crash, hang or finding that file is the input to replay.
//
// A finding aborts, as under libFuzzer (a mutant running over 10 s counts as a hang); the count
// is printed at the end.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);

namespace {

using Bytes = std::string;

// Numbers a parser or a header is most likely to mishandle.
const char* const kNumbers[] = {"0", "-1", "1", "-0", "1e308", "-1e308", "1e-320", "nan", "inf",
                                "-inf", "2147483648", "9223372036854775808", "4294967295",
                                "0.5", "1e9", "-2", "3"};
const uint8_t kBytes[] = {0x00, 0xff, 0x7f, 0x80, 0x01, '\n', ':', '{', '}', '[', ']', '-', ',',
                          '"', '\'', '#', '&', '*', '!', ' ', '.'};

class Mutator {
 public:
  Mutator(uint64_t seed, const std::vector<Bytes>& corpus) : rng_(seed), corpus_(corpus) {}

  Bytes Next() {
    Bytes b = corpus_[Pick(corpus_.size())];
    const int edits = 1 + int(Pick(8));
    for (int e = 0; e < edits; ++e) Edit(b);
    if (b.size() > kMaxSize) b.resize(kMaxSize);
    return b;
  }

 private:
  static constexpr size_t kMaxSize = 1 << 20;

  size_t Pick(size_t n) { return n == 0 ? 0 : size_t(rng_() % n); }

  void Edit(Bytes& b) {
    const size_t n = b.size();
    switch (Pick(9)) {
      case 0:  // flip a bit
        if (n) b[Pick(n)] ^= char(1u << Pick(8));
        break;
      case 1:  // a random byte
        if (n) b[Pick(n)] = char(rng_());
        break;
      case 2:  // an interesting byte, replaced or inserted
        if (n && Pick(2)) b[Pick(n)] = char(kBytes[Pick(sizeof kBytes)]);
        else b.insert(b.begin() + long(Pick(n + 1)), char(kBytes[Pick(sizeof kBytes)]));
        break;
      case 3: {  // erase a range
        if (!n) break;
        const size_t at = Pick(n);
        b.erase(at, 1 + Pick(std::min<size_t>(n - at, 64)));
        break;
      }
      case 4: {  // duplicate a range somewhere
        if (!n) break;
        const size_t at = Pick(n);
        const Bytes piece = b.substr(at, 1 + Pick(std::min<size_t>(n - at, 64)));
        b.insert(Pick(b.size() + 1), piece);
        break;
      }
      case 5: {  // splice: this one's head, another's tail
        const Bytes& o = corpus_[Pick(corpus_.size())];
        b = b.substr(0, Pick(n + 1)) + o.substr(Pick(o.size() + 1));
        break;
      }
      case 6: {  // a run of digits (a number) rewritten as an interesting one
        if (!n) break;
        size_t at = Pick(n);
        while (at < n && !std::isdigit(static_cast<unsigned char>(b[at]))) ++at;
        if (at == n) break;
        size_t end = at;
        while (end < n && (std::isdigit(static_cast<unsigned char>(b[end])) || b[end] == '.' ||
                           b[end] == 'e' || b[end] == '-'))
          ++end;
        b.replace(at, end - at, kNumbers[Pick(std::size(kNumbers))]);
        break;
      }
      case 7: {  // a little-endian integer field overwritten (binary headers: STL, PLY, HDF5)
        if (n < 8) break;
        const size_t at = Pick(n - 7);
        const uint64_t v = Pick(2) ? rng_() : (uint64_t(1) << Pick(64)) - Pick(2);
        std::memcpy(&b[at], &v, size_t(1) << Pick(4));
        break;
      }
      default:  // truncate
        b.resize(Pick(n + 1));
        break;
    }
  }

  std::mt19937_64 rng_;
  const std::vector<Bytes>& corpus_;
};

// A mutant that runs longer than kHangSeconds is a hang (a finding, as libFuzzer's -timeout):
// SIGALRM prints where the input is and aborts.
constexpr unsigned kHangSeconds = 10;
char g_hang_message[512];
void OnHang(int) {
  const ssize_t n = write(2, g_hang_message, std::strlen(g_hang_message));
  (void)n;
  std::abort();
}

bool Flag(const std::string& a, const char* name, std::string& value) {
  const std::string prefix = std::string("-") + name + "=";
  if (a.rfind(prefix, 0) != 0) return false;
  value = a.substr(prefix.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  double mutate_seconds = 0;
  uint64_t seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    std::string value;
    if (Flag(a, "mutate_seconds", value)) {
      mutate_seconds = std::atof(value.c_str());
      continue;
    }
    if (Flag(a, "seed", value)) {
      seed = std::strtoull(value.c_str(), nullptr, 10);
      continue;
    }
    if (a.rfind("-", 0) == 0) continue;
    const fs::path p = fs::absolute(a);  // before LLVMFuzzerInitialize may change directory
    if (fs::is_directory(p)) {
      for (const auto& e : fs::recursive_directory_iterator(p))
        if (e.is_regular_file()) files.push_back(e.path());
    } else {
      files.push_back(p);
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "usage: %s [-mutate_seconds=S] [-seed=N] FILE_OR_FOLDER...: no input files\n",
                 argv[0]);
    return 2;
  }
  const std::string target = fs::path(argv[0]).filename().string();
  if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
  std::vector<Bytes> corpus;
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    Bytes bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      std::fprintf(stderr, "cannot read %s\n", f.c_str());
      return 2;
    }
    std::fprintf(stderr, "replay %s (%zu bytes)\n", f.filename().c_str(), bytes.size());
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    corpus.push_back(std::move(bytes));
  }
  std::printf("replayed %zu inputs, no finding\n", files.size());
  if (mutate_seconds <= 0) return 0;

  const char* tmp = std::getenv("TMPDIR");
  const std::string last = std::string(tmp ? tmp : "/tmp") + "/surge_fuzz_last_" + target + "_" +
                           std::to_string(getpid());
  std::printf("mutating for %g s, seed %llu; the running input is kept in %s\n", mutate_seconds,
              static_cast<unsigned long long>(seed), last.c_str());
  std::fflush(stdout);
  std::snprintf(g_hang_message, sizeof g_hang_message,
                "FUZZ FINDING: an input ran longer than %u s (a hang); it is in %s\n", kHangSeconds,
                last.c_str());
  std::signal(SIGALRM, OnHang);
  Mutator mutator(seed, corpus);
  const auto start = std::chrono::steady_clock::now();
  uint64_t runs = 0;
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
         mutate_seconds) {
    const Bytes b = mutator.Next();
    {
      std::ofstream out(last, std::ios::binary | std::ios::trunc);
      out.write(b.data(), std::streamsize(b.size()));
    }
    alarm(kHangSeconds);
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(b.data()), b.size());
    alarm(0);
    ++runs;
  }
  std::remove(last.c_str());
  std::printf("mutated %llu inputs in %g s (seed %llu), no finding\n",
              static_cast<unsigned long long>(runs), mutate_seconds,
              static_cast<unsigned long long>(seed));
  return 0;
}

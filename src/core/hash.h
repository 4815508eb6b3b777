// FNV-1a (64 bit) content hashes, as 16 hex digits: the scene text and resolved scene in results
// and checkpoints (restart and sweep compare them), and the bytes of every mesh file a scene
// names (docs/robustness.md). Not cryptographic: it tells changed inputs apart, nothing more.
#pragma once
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace surge {

// Feeds `bytes` into the running FNV-1a state `h` (start from kFnv1aBasis).
constexpr uint64_t kFnv1aBasis = 1469598103934665603ull;  // FNV-1a 64 offset basis
inline uint64_t Fnv1a(std::string_view bytes, uint64_t h = kFnv1aBasis) {
  for (unsigned char ch : bytes) {
    h ^= ch;
    h *= 1099511628211ull;  // FNV 64-bit prime
  }
  return h;
}

inline std::string HashHex(uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// FNV-1a of `text` in hex.
inline std::string Fnv1aHex(std::string_view text) { return HashHex(Fnv1a(text)); }

}  // namespace surge

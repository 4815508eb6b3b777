#include "core/simd.h"

#include <atomic>

namespace surge {
namespace {

bool CpuHasWide() {
#if SURGE_HAVE_WIDE_SIMD
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx");
#else
  return false;
#endif
}

std::atomic<bool>& WideFlag() {
  static std::atomic<bool> flag{CpuHasWide()};
  return flag;
}

}  // namespace

bool WideSimd() { return WideFlag().load(std::memory_order_relaxed); }

bool SetWideSimd(bool on) { return WideFlag().exchange(on && CpuHasWide()); }

}  // namespace surge

// Lane vectors of doubles (GCC/Clang vector extensions) for the transfer kernels' node sums.
// Each lane is an independent IEEE operation, so a kernel written with Real2 or Real4 gives bitwise
// the same result whether the compiler emits SSE2, AVX or NEON instructions; no sum is
// reassociated. Used only inside inline kernels (no lane vector in function signatures: the
// vector ABI differs between instruction sets).
//
// Wide kernels: a hot loop may come in two builds of one always-inline body, a portable one and
// one compiled for AVX (SURGE_TARGET_WIDE), whose Real4 node updates do in one instruction what
// the portable build does in two Real2 ones, lane for lane the same operations. WideSimd() picks
// the AVX build at run time where the CPU has AVX; results are bitwise the same either way
// (tests/unit/transfer/transfer_test.cpp, "WideKernels…").
#pragma once

#include "core/math.h"

namespace surge {

typedef Real Real2 __attribute__((vector_size(2 * sizeof(Real))));
typedef Real Real4 __attribute__((vector_size(4 * sizeof(Real))));

#if defined(__x86_64__) || defined(__i386__)
#define SURGE_HAVE_WIDE_SIMD 1
#define SURGE_TARGET_WIDE __attribute__((target("avx")))
#else
#define SURGE_HAVE_WIDE_SIMD 0
#define SURGE_TARGET_WIDE
#endif

// True when the wide (AVX) builds of the transfer kernels run: the CPU has AVX and SetWideSimd
// has not turned them off.
bool WideSimd();
// Turns the wide kernels off (or back on where the CPU has AVX); returns the previous setting.
// For tests and benchmarks that compare the two builds.
bool SetWideSimd(bool on);

}  // namespace surge

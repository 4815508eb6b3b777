// Two-lane double vectors (GCC/Clang vector extensions) for the transfer kernels' node sums.
// Each lane is an independent IEEE operation, so a kernel written with Real2 gives bitwise the
// same result whether the compiler emits SSE2, AVX or NEON instructions; no
// sum is reassociated. Used only inside inline kernels (no Real2 in function signatures: the
// vector ABI differs between instruction sets).
#pragma once

#include "core/math.h"

namespace surge {

typedef Real Real2 __attribute__((vector_size(2 * sizeof(Real))));

}  // namespace surge

// Random deformation paths for the material-point driver tests (fixed seeds, STYLE H.9).
#pragma once
#include <random>

#include "core/math.h"

namespace surge::testing {

// A velocity gradient with independent entries uniform in [-rate, rate] [1/s].
inline Mat3 RandomL(std::mt19937_64& rng, Real rate) {
  std::uniform_real_distribution<Real> u(-rate, rate);
  Mat3 L;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) L(i, j) = u(rng);
  return L;
}

}  // namespace surge::testing

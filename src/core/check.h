// Invariant checks (STYLE H.7): SURGE_ASSERT is debug-only (hot loops), SURGE_CHECK always on.
#pragma once
#include <cassert>
#include <stdexcept>
#include <string>

#define SURGE_ASSERT(cond) assert(cond)
#define SURGE_CHECK(cond, msg)                                                          \
  do {                                                                                  \
    if (!(cond))                                                                        \
      throw std::logic_error(std::string("check failed: " #cond ": ") + (msg) + " (" + \
                             __FILE__ + ":" + std::to_string(__LINE__) + ")");         \
  } while (0)

// Runs a loaded scene in-process for tests: Step() until `end`, calling observe(state, report)
// after every step. Fails the test (and stops) when the health check trips.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "step/stages.h"
#include "step/step.h"

namespace surge::testing {

inline std::string ScenePath(const std::string& name) {
  return std::string(SURGE_SOURCE_DIR) + "/scenes/" + name;
}

// Scene overrides for by-hand studies: the comma-separated key=value list in environment variable
// `name` (as `surge run --set`), appended to `out`. Nothing when the variable is unset.
inline std::vector<std::string> EnvOverrides(const char* name, std::vector<std::string> out = {}) {
  if (const char* extra = std::getenv(name)) {
    const std::string all(extra);
    for (size_t begin = 0; begin <= all.size();) {
      const size_t end = std::min(all.find(',', begin), all.size());
      if (end > begin) out.push_back(all.substr(begin, end - begin));
      begin = end + 1;
    }
  }
  return out;
}

template <typename Observe>
void RunUntil(LoadedScene& scene, Real end, Observe&& observe) {
  scene.model.time.end = end;
  const Pipeline pipeline = MakePipeline(scene.model);
  Workspace work;
  StepReport report;
  while (scene.state.time < end * (1 - 1e-12)) {
    Step(scene.model, pipeline, scene.state, work, report);
    ASSERT_EQ(report.health.status, HealthStatus::kOk) << report.health.detail;
    observe(scene.state, report);
  }
}

// Times at which a sampled signal crosses zero (linear interpolation between samples).
inline std::vector<Real> ZeroCrossings(const std::vector<Real>& t, const std::vector<Real>& y) {
  std::vector<Real> out;
  for (size_t i = 1; i < y.size(); ++i)
    if ((y[i - 1] < 0) != (y[i] < 0) && y[i] != y[i - 1])
      out.push_back(t[i - 1] + (t[i] - t[i - 1]) * (0 - y[i - 1]) / (y[i] - y[i - 1]));
  return out;
}

// Mean period from successive zero crossings: 2 x the mean spacing of all crossings.
inline Real PeriodFromCrossings(const std::vector<Real>& c) {
  if (c.size() < 2) return 0;
  return 2.0 * (c.back() - c.front()) / Real(c.size() - 1);
}

}  // namespace surge::testing

// Fuzz target: scene parser and builder (LoadSceneFromString: YAML -> SceneSpec -> Model + State,
// meshes read, particles seeded). Input: leading lines "--set key.path=value" are taken as
// command-line overrides, the rest is the scene text. Contract checked: every rejection is a
// SceneError naming the file ("fuzz.yaml", or "--set ..." for an override), with a line for
// errors in the file; any other exception, a crash, a hang or a sanitizer report is a finding.
// Relative mesh paths resolve from tests/data/scenes (the corpus's meshes). Seeding is bounded
// by SURGE_MEMORY_LIMIT, 4 MiB unless set in the environment (about 5000 particles and 60 grid
// blocks: seeding dominates the time of an input), which the builder enforces.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "fuzz/fuzz_util.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  setenv("SURGE_MEMORY_LIMIT", "4194304", 0);
  if (chdir(SURGE_SOURCE_DIR "/tests/data/scenes") != 0) surge::fuzz::Finding("chdir");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  while (text.rfind("--set ", 0) == 0) {
    const size_t nl = text.find('\n');
    overrides.push_back(text.substr(6, nl == std::string::npos ? std::string::npos : nl - 6));
    text = nl == std::string::npos ? std::string() : text.substr(nl + 1);
  }
  try {
    const surge::LoadedScene scene = surge::LoadSceneFromString(text, "fuzz.yaml", overrides);
    if (scene.resolved_yaml.empty()) surge::fuzz::Finding("empty resolved scene");
  } catch (const surge::SceneError& e) {
    const bool from_set = e.file().rfind("--set ", 0) == 0;
    if (e.file() != "fuzz.yaml" && !from_set)
      surge::fuzz::Finding(std::string("SceneError without the file name: ") + e.what());
    if (e.message().empty()) surge::fuzz::Finding(std::string("SceneError without a message: ") + e.what());
  } catch (const std::exception& e) {
    surge::fuzz::Finding(std::string("not a SceneError: ") + e.what());
  }
  return 0;
}

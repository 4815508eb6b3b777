// Advice about a valid scene that is likely to give poor results (printed by `surge check`,
// logged by `surge run`); never an error.
#pragma once
#include <string>
#include <vector>

namespace surge {

struct LoadedScene;

std::vector<std::string> SceneWarnings(const LoadedScene& scene);

}  // namespace surge

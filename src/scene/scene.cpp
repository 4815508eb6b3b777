// LoadScene / LoadSceneFromString: read the text, parse (scene_parser.cpp), build
// (scene_builder.cpp), and echo the resolved spec.
#include "scene/scene.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "scene/scene_builder.h"
#include "scene/scene_spec.h"

namespace surge {
namespace {

LoadedScene Load(std::string path, std::string text, const std::string& source,
                 const std::string& base_dir, const std::vector<std::string>& overrides,
                 const std::function<void(const std::string&)>& before_build = {}) {
  LoadedScene scene;
  const SceneSpec spec = ParseSceneSpec(text, source, base_dir, overrides);
  if (before_build) before_build(spec.name);
  BuildScene(spec, scene.model, scene.state);
  scene.path = std::move(path);
  scene.text = std::move(text);
  scene.resolved_yaml = SceneSpecToYaml(spec);
  scene.parameters = spec.parameters;
  return scene;
}

}  // namespace

std::vector<std::string> MaterialModelNames() {
  std::vector<std::string> names;
  for (const MaterialKind& k : MaterialKinds()) names.push_back(k.name);
  return names;
}

LoadedScene LoadScene(const std::string& path, const std::vector<std::string>& overrides,
                      const std::function<void(const std::string&)>& before_build) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    const bool exists = std::filesystem::exists(path, ec);
    throw SceneError(path, 0, 0, "",
                     exists ? "cannot read scene file: not a regular file"
                            : "cannot read scene file: no such file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw SceneError(path, 0, 0, "", std::string("cannot read scene file: ") + std::strerror(errno));
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw SceneError(path, 0, 0, "", "cannot read scene file: read error");
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  const std::string dir = parent.empty() ? std::string(".") : parent.string();
  return Load(path, std::move(text), path, dir, overrides, before_build);
}

LoadedScene LoadSceneFromString(const std::string& text, const std::string& name_for_errors,
                                const std::vector<std::string>& overrides) {
  return Load("<string>", text, name_for_errors, ".", overrides);
}

}  // namespace surge

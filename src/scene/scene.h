// Public scene API: scene file (YAML, docs/scene-reference.md) -> Model + State.
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/model.h"
#include "core/state.h"
#include "scene/scene_error.h"

namespace surge {

struct LoadedScene {
  std::string path;           // file path, or "<string>" for LoadSceneFromString
  std::string text;           // the scene file verbatim
  std::string resolved_yaml;  // the parsed spec with every default filled in, as YAML
  std::vector<std::pair<std::string, Real>> parameters;  // `parameters:` after --set
  Model model;
  State state;  // particles seeded, grouped by material (stable sort), groups filled
};

// Reads, validates and builds the scene in `path`. `overrides` are "key.path=value" strings (as
// given to --set), applied to the YAML tree before validation; list indices are numbers
// ("bodies.0.velocity=[2,0,0]"). Relative mesh paths are taken from the scene file's directory.
// Throws SceneError (file:line:column: key.path: message) on any problem with the input.
// `before_build`, when set, is called with the scene's name once the file is parsed and valid and
// before anything is built or seeded (`surge run` refuses an existing result there, so a large
// scene does not seed for minutes only to be refused); what it throws propagates.
LoadedScene LoadScene(const std::string& path, const std::vector<std::string>& overrides = {},
                      const std::function<void(const std::string& name)>& before_build = {});

// As LoadScene, from text; `name_for_errors` stands for the file name in errors, and relative
// mesh paths are taken from the current directory.
LoadedScene LoadSceneFromString(const std::string& text, const std::string& name_for_errors,
                                const std::vector<std::string>& overrides = {});

// The mesh files a resolved scene (SceneSpecToYaml) names, with their content hashes: (file,
// file_hash) for every map holding both, in document order. Empty for text that is not YAML.
std::vector<std::pair<std::string, std::string>> MeshFileHashes(const std::string& resolved_yaml);

// Names accepted by `model:` in a scene's materials, in table order (scene/material_kinds.cpp).
std::vector<std::string> MaterialModelNames();

}  // namespace surge

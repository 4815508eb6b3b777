// Scene builder: validated SceneSpec -> Model + State (internal to surge_scene).
#pragma once
#include "core/model.h"
#include "core/state.h"
#include "scene/scene_spec.h"

namespace surge {

// Fills `model` and seeds `state.particles` (grouped by material, groups filled).
// Reads mesh files. Throws SceneError for problems only visible after seeding (empty regions,
// particles outside the domain, unreadable or open meshes, too many particles).
void BuildScene(const SceneSpec& spec, Model& model, State& state);

}  // namespace surge

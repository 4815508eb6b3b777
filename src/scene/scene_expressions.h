// Arithmetic in scene files: a value written `${expr}` is evaluated over the scene's
// `parameters:` (docs/scene-reference.md). muParser does the parsing; this is its only user.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "core/math.h"

namespace surge {

using SceneParameters = std::vector<std::pair<std::string, Real>>;

// Value of `expr` (the text between "${" and "}") with the given named values. On failure
// returns false and sets `error` to a one-line reason (unknown name, syntax, not finite).
bool EvaluateSceneExpression(const std::string& expr, const SceneParameters& parameters,
                             Real& value, std::string& error);

}  // namespace surge

// `${expr}` evaluation with muParser (one instance per expression; scenes hold a handful).
#include "scene/scene_expressions.h"

#include <muParser.h>

#include <cmath>

namespace surge {

bool EvaluateSceneExpression(const std::string& expr, const SceneParameters& parameters,
                             Real& value, std::string& error) {
  try {
    mu::Parser parser;
    std::vector<double> storage(parameters.size());  // muParser binds variables by address
    for (size_t i = 0; i < parameters.size(); ++i) {
      storage[i] = parameters[i].second;
      parser.DefineVar(parameters[i].first, &storage[i]);
    }
    parser.SetExpr(expr);
    value = parser.Eval();
  } catch (const mu::Parser::exception_type& e) {
    error = e.GetMsg();
    return false;
  }
  if (!std::isfinite(value)) {
    error = "the value is not finite";
    return false;
  }
  return true;
}

}  // namespace surge

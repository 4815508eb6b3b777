// Scene advice: numerics known to misbehave, and weakly compressible fluids run too close to
// their (possibly reduced) sound speed.
#include "app/scene_warnings.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <variant>

#include "scene/scene.h"

namespace surge {

std::vector<std::string> SceneWarnings(const LoadedScene& scene) {
  std::vector<std::string> out;
  const Model& m = scene.model;
  if (m.shape == ShapeFunction::kLinear && m.scheme == UpdateScheme::kUsl)
    out.push_back(
        "grid: linear shape functions with update: usl suffer the cell-crossing instability; "
        "consider grid.update: musl or a B-spline (docs/validation.md)");

  // Weak compressibility holds while the flow Mach number stays below about 0.1 (Monaghan 1994:
  // density fluctuations scale with Ma^2, so Ma < 0.1 keeps them below 1 %). Flow speed estimate
  // per body: initial speed plus the free-fall speed sqrt(2 |g| dh) from the body's top down to
  // the lowest point of the domain along gravity.
  const Real g = m.gravity.norm();
  const Vec3 down = g > 0 ? Vec3(m.gravity / g) : Vec3::Zero();
  Real floor = 0;  // largest coordinate of the domain along `down`
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? m.domain_max.x() : m.domain_min.x(),
                      (c & 2) ? m.domain_max.y() : m.domain_min.y(),
                      (c & 4) ? m.domain_max.z() : m.domain_min.z());
    floor = c == 0 ? down.dot(corner) : std::max(floor, down.dot(corner));
  }
  const Particles& P = scene.state.particles;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const Material& mat = m.materials[m.bodies[b].material];
    const bool fluid = std::visit(
        [](const auto& p) { return kIsFluid<std::decay_t<decltype(p)>>; }, mat.params);
    if (!fluid) continue;
    Real speed = 0, top = floor;
    for (size_t p = 0; p < P.size(); ++p) {
      if (P.body[p] != int(b)) continue;
      speed = std::max(speed, P.v[p].norm());
      top = std::min(top, down.dot(P.x[p]));
    }
    const Real v = speed + std::sqrt(2.0 * g * std::max(floor - top, 0.0));
    const Real c = WaveSpeed(mat);
    const Real mach = v / c;
    if (mach > 0.1)
      out.push_back(fmt::format(
          "materials.{}: estimated flow speed {:.3g} m/s in body '{}' (initial speed + free fall "
          "to the domain floor) is Mach {:.2f} for the sound speed sqrt(K/rho) = {:.3g} m/s; "
          "weak compressibility needs Mach < 0.1: raise bulk_modulus to at least {:.3g} Pa",
          mat.name, v, m.bodies[b].name, mach, c, mat.density * 100.0 * v * v));
  }
  return out;
}

}  // namespace surge

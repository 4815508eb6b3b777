// Scene advice: numerics known to misbehave, and weakly compressible fluids run too close to
// their (possibly reduced) sound speed.
#include "app/scene_warnings.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>

#include "scene/scene.h"

namespace surge {

namespace {

// Obstacles the node contact cannot represent well (issue #5, docs/scene-reference.md
// `obstacles`): thinner than two cells (nodes on both sides share one velocity, so material can
// leak through), outside the domain (never touched), and box faces off the grid planes (the
// seed's structures sit on grid planes, Mast 2013 §7.4; off-plane faces start the contact up to
// one cell early).
void ObstacleWarnings(const Model& m, std::vector<std::string>& out) {
  for (size_t o = 0; o < m.obstacles.size(); ++o) {
    const Obstacle& ob = m.obstacles[o];
    Real thickness = std::numeric_limits<Real>::infinity();
    std::visit(
        [&](const auto& s) {
          using S = std::decay_t<decltype(s)>;
          if constexpr (std::is_same_v<S, BoxShape>) {
            for (int a = 0; a < m.dim; ++a) thickness = std::min(thickness, s.max[a] - s.min[a]);
          } else if constexpr (std::is_same_v<S, SphereShape>) {
            thickness = 2 * s.radius;
          } else if constexpr (std::is_same_v<S, CylinderShape>) {
            thickness = std::min(2 * s.radius, (s.top - s.base).norm());
          } else if constexpr (std::is_same_v<S, PolygonShape>) {
            // The smallest width across one of its edges: the largest distance of a vertex from
            // the edge's line, minimised over the edges (the exact minimum width of a convex
            // polygon; a plate leaning at any angle is caught, unlike by its bounding box).
            const size_t n = s.points.size();
            for (size_t k = 0; k < n; ++k) {
              const auto& a = s.points[k];
              const auto& b = s.points[(k + 1) % n];
              const Real ex = b[0] - a[0], ey = b[1] - a[1], len = std::hypot(ex, ey);
              if (!(len > 0)) continue;
              Real width = 0;
              for (const auto& p : s.points)
                width = std::max(width, std::abs(ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / len);
              thickness = std::min(thickness, width);
            }
            if (m.dim == 3) thickness = std::min(thickness, s.z1 - s.z0);
          } else if constexpr (!std::is_same_v<S, PlaneShape>) {
            for (int a = 0; a < m.dim; ++a)
              thickness = std::min(thickness, ob.bounds_max[a] - ob.bounds_min[a]);
          }
        },
        ob.shape);
    if (thickness < 2 * m.dx)
      out.push_back(fmt::format(
          "obstacles[{}] '{}': {:.3g} m thick, less than two cells ({:.3g} m); grid nodes on both "
          "sides share one velocity and material may pass through: make it thicker or refine "
          "grid.cell_size",
          o, ob.name, thickness, 2 * m.dx));
    bool outside = false;
    for (int a = 0; a < m.dim; ++a)
      outside |= ob.bounds_max[a] < m.domain_min[a] || ob.bounds_min[a] > m.domain_max[a];
    if (outside && ob.motion.kind == ObstacleMotionKind::kFixed)
      out.push_back(fmt::format("obstacles[{}] '{}': lies outside the domain; nothing can touch it",
                                o, ob.name));
    if (const auto* box = std::get_if<BoxShape>(&ob.shape)) {
      bool off = false;
      for (int a = 0; a < m.dim; ++a) {
        for (Real c : {box->min[a], box->max[a]}) {
          const Real cells = c / m.dx;
          off |= std::abs(cells - std::round(cells)) > 1e-6;
        }
      }
      if (off && ob.motion.kind == ObstacleMotionKind::kFixed)
        out.push_back(fmt::format(
            "obstacles[{}] '{}': box faces do not lie on grid planes (multiples of cell_size "
            "{:.6g} m); the contact then acts up to one cell before the face (Mast 2013 §7.4 "
            "keeps structures on grid planes)",
            o, ob.name, m.dx));
    }
  }
}

// The anti-locking settings of a body, or null without any.
const AntiLocking* AntiLockingOf(const Model& m, const BodyInfo& body) {
  if (body.antilocking < 0 || size_t(body.antilocking) >= m.antilocking.size()) return nullptr;
  return &m.antilocking[size_t(body.antilocking)];
}

}  // namespace

std::vector<std::string> SceneWarnings(const LoadedScene& scene) {
  std::vector<std::string> out;
  const Model& m = scene.model;
  // With transfer: apic the blow-up comes even in free translation (docs/stability.md, "Linear
  // shape functions with APIC": 32 ms at Courant number 0.4, USL's stress update takes the full
  // increment of a node that a particle has just reached); linear + apic + musl is stable since
  // issue #8's fix and gets no warning.
  if (m.shape == ShapeFunction::kLinear && m.scheme == UpdateScheme::kUsl)
    out.push_back(
        std::string("grid: linear shape functions with update: usl suffer the cell-crossing "
                    "instability") +
        (m.transfer == TransferScheme::kApic
             ? " (with transfer: apic even a freely translating body blows up)"
             : "") +
        "; consider grid.update: musl or a B-spline (docs/validation.md, docs/stability.md)");

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
  ObstacleWarnings(m, out);
  // Two folding walls fewer than three cells apart fold their ghosts onto the same node planes:
  // a floating box in a slab two cells thick tilts and sinks 11 % too deep under fold_all,
  // against 1.6 % three cells apart (rigid_coupling_test, docs/walls.md).
  if (m.ghost_nodes == GhostNodes::kFoldAll && m.shape != ShapeFunction::kLinear) {
    for (int d = 0; d < m.dim; ++d) {
      const Wall& lo = m.walls[size_t(2 * d)];
      const Wall& hi = m.walls[size_t(2 * d + 1)];
      const Real cells = (m.domain_max[d] - m.domain_min[d]) / m.dx;
      if (lo.kind == WallKind::kOpen || hi.kind == WallKind::kOpen || cells >= 3 - 1e-9) continue;
      out.push_back(fmt::format(
          "domain.ghost_nodes: fold_all with the walls {} and {} only {:.3g} cells apart folds "
          "both walls' ghost nodes onto the same node planes (a floating box tilts, "
          "docs/walls.md); keep them at least 3 cells apart or use mirror",
          FaceName(Face(2 * d)), FaceName(Face(2 * d + 1)), cells));
    }
  }
  // Stress averaging on node supports (method node or hybrid, `stress: true`) projects the total
  // mean stress over overlapping supports: an elastic cantilever at nu = 0.49 then loses its
  // oscillation, as with `strain: total` (antilocking_test, docs/antilocking.md).
  for (const BodyInfo& body : m.bodies) {
    const Material& mat = m.materials[size_t(body.material)];
    const bool fluid = std::visit(
        [](const auto& p) { return kIsFluid<std::decay_t<decltype(p)>>; }, mat.params);
    const AntiLocking* al = AntiLockingOf(m, body);
    if (fluid || !al) continue;
    if (al->stress && (al->method == AntiLockingMethod::kNode || al->method == AntiLockingMethod::kHybrid))
      out.push_back(fmt::format(
          "body '{}' (material '{}'): stress averaging on node supports (antilocking method {}, "
          "stress: true) smooths the total mean stress of a solid and damps its bending (an "
          "incompressible cantilever stops oscillating, docs/antilocking.md); use method: cell "
          "or stress: false",
          body.name, mat.name, al->method == AntiLockingMethod::kNode ? "node" : "hybrid"));
  }
  // Water brought to rest by local damping under node-based AS1 (the Newtonian fluid's default):
  // the node average is the support's centroid value, half a cell inside a wall or the surface,
  // and the particles crowd at the floor over seconds (the settled barrier's pressure RMS 7.3 %
  // at 4 s and 8.5 % at 8 s, against 1.8-1.9 % with the settle recipe; docs/antilocking.md,
  // "Linear node fit"). Damping for a second or more marks a scene run for its settled state
  // (a short damped start, as in scenes/studies/hydrostatic_tank_2d.yaml, 0.5 s, crowds little).
  if (m.damping.alpha > 0 && std::min(m.damping.until, m.time.end) >= 1.0) {
    for (const BodyInfo& body : m.bodies) {
      const Material& mat = m.materials[size_t(body.material)];
      const AntiLocking* al = AntiLockingOf(m, body);
      if (!std::holds_alternative<NewtonianFluidParams>(mat.params) || !al ||
          al->method != AntiLockingMethod::kNode || al->linear_trace ||
          al->approach != AntiLockingApproach::kVolumetric)
        continue;
      out.push_back(fmt::format(
          "body '{}' (material '{}'): water settled by damping under node-based anti-locking "
          "crowds at the floor (pressure 7-9 % RMS off hydrostatic after 4-8 s); for the settled "
          "state use antilocking {{method: node, fit: linear}} with domain.ghost_nodes: fold_all "
          "and particle_shifting: true (docs/antilocking.md, \"Linear node fit\")",
          body.name, mat.name));
    }
  }
  // A floating obstacle in water under node-based AS1 without particle shifting: each particle's
  // J is replaced by its supports' mean, so particles pressed together meet no pressure and crowd
  // at the floor (1.4x their space in the bottom band by 2 s), and a floating body rides the
  // crowding water down: 4.5 mm in 2 s at h = 0.02 m, 35 % too deep by 4 s
  // (rigid_coupling_test, NodeAntiLockingLetsTheFloatingBoxSinkUnlessTheParticlesShift).
  // A body that may float: its density, or its mass over its bounding box's volume (at most its
  // true density; a box's exactly), below the water's. A boulder on the floor does not warn.
  auto lightest = std::numeric_limits<Real>::infinity();
  for (const Obstacle& o : m.obstacles) {
    if (o.motion.kind != ObstacleMotionKind::kDynamic) continue;
    Real volume = 1;
    for (int a = 0; a < 3; ++a) volume *= o.bounds_max[a] - o.bounds_min[a];
    lightest = std::min(lightest, o.motion.density > 0 ? o.motion.density : o.motion.mass / volume);
  }
  for (const BodyInfo& body : m.bodies) {
    const Material& mat = m.materials[size_t(body.material)];
    const AntiLocking* al = AntiLockingOf(m, body);
    if (!std::holds_alternative<NewtonianFluidParams>(mat.params) || !al ||
        al->method != AntiLockingMethod::kNode || mat.particle_shifting ||
        !(lightest < mat.density))
      continue;
    out.push_back(fmt::format(
        "body '{}' (material '{}'): under node-based anti-locking the water's particles crowd at "
        "the floor and a floating (dynamic) obstacle sinks steadily (35 % below its Archimedes "
        "draft after 4 s in rigid_coupling_test); set particle_shifting: true (the sinking stops; "
        "the body may rock by a few degrees) or antilocking {{method: none}} "
        "(docs/antilocking.md, \"Crowding\")",
        body.name, mat.name));
  }
  // A Mohr-Coulomb tension cut-off at or above the apex c cot(phi) never acts: the apex already
  // bounds the mean tension (materials/mohr_coulomb.h).
  for (const Material& mat : m.materials) {
    if (const auto* mc = std::get_if<MohrCoulombParams>(&mat.params)) {
      const Real s = std::sin(mc->friction_angle);
      if (std::isfinite(mc->tension_cutoff) && s > 0 &&
          mc->tension_cutoff >= mc->cohesion * std::cos(mc->friction_angle) / s)
        out.push_back(fmt::format(
            "materials.{}: tension_cutoff {:.4g} Pa is at or above the apex c cot(phi) = {:.4g} "
            "Pa and has no effect",
            mat.name, mc->tension_cutoff, mc->cohesion * std::cos(mc->friction_angle) / s));
    }
  }
  // A geostatic start is the stress under full gravity: ramping gravity up from zero unloads the
  // layer first, which yields towards the passive side and ends near the elastic K0 = nu/(1-nu)
  // instead (measured: -13 % thrust against Jaky, obstacle_mesh_test).
  if (m.gravity_ramp > 0) {
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      bool prestressed = false;
      for (size_t p = 0; p < P.size() && !prestressed; ++p)
        prestressed = P.body[p] == int(b) && !P.stress[p].isZero();
      if (prestressed)
        out.push_back(fmt::format(
            "bodies[{}] '{}': starts with a geostatic stress while gravity_ramp = {:.3g} s; the "
            "ramp unloads the layer first (it can yield and end near the elastic K0): use "
            "gravity_ramp: 0 with a geostatic start",
            b, m.bodies[b].name, m.gravity_ramp));
    }
  }
  return out;
}

}  // namespace surge

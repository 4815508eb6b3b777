// Scene builder: SceneSpec -> Model + State. Holds the one table of material kinds
// (STYLE H.5), seeds every body (particle_sampling.cpp), sets initial stress and tractions, and
// groups the particles by material.
#include "scene/scene_builder.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <type_traits>
#include <utility>
#include <variant>
#include <string>

#include "contact/geometry.h"
#include "contact/mesh_distance.h"
#include "core/log.h"
#include "materials/update_stress.h"
#include "mesh/mesh.h"
#include "scene/memory_estimate.h"
#include "step/step.h"
#include "scene/particle_sampling.h"
#include "scene/scene_error.h"

namespace surge {
namespace {

// Total particles allowed in one scene, and lattice candidates scanned for one body.
constexpr double kMaxParticles = 2e8;
constexpr double kMaxCandidates = 4e8;

std::string BodyPath(size_t b) { return "bodies[" + std::to_string(b) + "]"; }

[[noreturn]] void Fail(const SourceLoc& loc, const std::string& path, const std::string& msg) {
  throw SceneError(loc.source, loc.line, loc.column, path, msg);
}

// Shortest decimal text that reads back to the same double.
std::string Num(Real v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string Point(const Vec3& x, int dim) {
  std::string s = "(";
  for (int a = 0; a < dim; ++a) s.append(a ? ", " : "").append(Num(x[a]));
  return s.append(")");
}

// Refuses the scene when a run of `particles` particles whose grid covers `box` (clipped to the
// domain) needs more memory than the machine has available (memory_estimate.h). `qualifier`
// ("at most ") says that the count is an upper bound.
void CheckMemory(const SceneSpec& spec, double particles, Aabb box, int fields,
                 const ParticleLayout& layout, const StepScratch& scratch,
                 const std::string& qualifier) {
  box.min = box.min.cwiseMax(spec.domain.min);
  box.max = box.max.cwiseMin(spec.domain.max);
  const MemoryEstimate m = EstimateMemory(
      particles, BlocksCovering(box.min, box.max, spec.grid.cell_size, spec.dimension), fields,
      spec.dimension, layout, scratch);
  const double available = AvailableMemory();
  if (m.total() <= available) return;
  const SourceLoc& loc = spec.bodies.empty() ? SourceLoc{} : spec.bodies.front().loc;
  Fail(loc, "bodies",
       "the run needs about " + FormatBytes(m.total()) + " of memory (" + qualifier +
           Num(std::round(particles)) + " particles x " + Num(BytesPerParticle(layout, scratch)) + " bytes + " +
           Num(m.grid_blocks) + " grid blocks x " + Num(BytesPerBlock(fields, spec.dimension, scratch)) +
           " bytes), more than the " + FormatBytes(available) +
           " available on this machine; use a larger grid.cell_size or fewer particles_per_cell");
}

// Particles of one body, in seeding order.
struct SeededBody {
  std::vector<Vec3> x;
  std::vector<Mat3> stress;
  std::vector<Vec3> ext_force;
  Real volume0 = 0;  // [m^3] (2-D: per 1 m thickness)
  Real mass = 0;     // [kg]
};

std::string ObstaclePath(size_t o) { return "obstacles[" + std::to_string(o) + "]"; }

// model.analysis: the scene's `analysis` with its defaults; the face must be one of the
// structure's (docs/scene-reference.md). Pre: model.obstacles, sensors and walls are built.
void BuildAnalysis(const SceneSpec& spec, Model& model) {
  model.analysis = ResolveAnalysis(spec, spec.analysis.settings).settings;
  const AnalysisSettings& a = model.analysis;
  if (a.face.empty()) return;
  std::vector<std::string> faces;
  if (a.structure == "domain") {
    for (int f = 0; f < 2 * model.dim; ++f)
      if (model.walls[f].kind != WallKind::kOpen) faces.push_back(FaceName(Face(f)));
  }
  for (const Obstacle& o : model.obstacles)
    if (o.name == a.structure) faces = o.faces;
  if (std::find(faces.begin(), faces.end(), a.face) != faces.end()) return;
  std::string list;
  for (const std::string& f : faces) list += (list.empty() ? "" : ", ") + f;
  Fail(spec.analysis.face_loc, "analysis.face",
       "structure '" + a.structure + "' has no face '" + a.face + "' (" +
           (faces.empty() ? std::string("it has no faces") : "its faces: " + list) + ")");
}

// Obstacle o of the spec as the run sees it: shape (meshes read, transformed and given their
// distance field), faces, bounds, reference point and motion.
Obstacle BuildObstacle(const SceneSpec& spec, size_t index) {
  const ObstacleSpec& os = spec.obstacles[index];
  const int dim = spec.dimension;
  Obstacle o;
  o.name = os.name;
  o.contact = os.contact;
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PlaneShape>) {
          o.shape = PlaneShape{s.point, s.normal.normalized()};  // the spec keeps it as given
        } else if constexpr (std::is_same_v<S, BoxRegion>) {
          o.shape = BoxShape{s.min, s.max};
        } else if constexpr (std::is_same_v<S, SphereRegion>) {
          o.shape = SphereShape{s.center, s.radius};
        } else if constexpr (std::is_same_v<S, CylinderRegion>) {
          o.shape = CylinderShape{s.base, s.top, s.radius};
        } else if constexpr (std::is_same_v<S, PolygonRegion>) {
          o.shape = PolygonShape{s.points, s.z0, s.z1};
        } else {
          const std::string path = ObstaclePath(index) + ".shape.mesh.file";
          TriangleMesh mesh;
          try {
            mesh = ReadTriangleMesh(s.file);
          } catch (const std::exception& e) {
            Fail(s.file_loc, path, e.what());
          }
          // x' = R (scale x) + t with R = Rz Ry Rx (rotate about x, then y, then z).
          constexpr Real kDeg = std::numbers::pi / 180.0;
          const Mat3 R = (Eigen::AngleAxis<Real>(s.rotate_deg.z() * kDeg, Vec3::UnitZ()) *
                          Eigen::AngleAxis<Real>(s.rotate_deg.y() * kDeg, Vec3::UnitY()) *
                          Eigen::AngleAxis<Real>(s.rotate_deg.x() * kDeg, Vec3::UnitX()))
                             .toRotationMatrix();
          for (Vec3& v : mesh.vertices) v = R * (s.scale * v) + s.translate;
          if (s.faces_by_normal) {
            // Faces by direction: each triangle joins the face of its normal's dominant axis and
            // sign, named like a box's faces (a pier's upstream nose is then mostly x-).
            mesh.part_names = {"x-", "x+", "y-", "y+", "z-", "z+"};
            mesh.part.assign(mesh.triangles.size(), 0);
            for (size_t k = 0; k < mesh.triangles.size(); ++k) {
              const auto& t = mesh.triangles[k];
              const Vec3 n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                 .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
              int axis = 0;
              n.cwiseAbs().maxCoeff(&axis);
              mesh.part[k] = 2 * axis + (n[axis] > 0 ? 1 : 0);
            }
          }
          MeshShape shape;
          shape.file = s.file;
          try {
            shape.field = std::make_shared<const MeshDistanceField>(std::move(mesh), s.one_sided);
          } catch (const std::exception& e) {
            Fail(s.file_loc, path, "mesh '" + s.file + "': " + e.what());
          }
          o.shape = std::move(shape);
        }
      },
      os.shape);
  o.faces = FaceNames(o.shape, dim);
  ReferenceBounds(o.shape, dim, o.bounds_min, o.bounds_max);
  if (os.reference_point) {
    o.reference_point = *os.reference_point;
  } else if (const auto* plane = std::get_if<PlaneShape>(&o.shape)) {
    o.reference_point = plane->point;
  } else {
    o.reference_point = 0.5 * (o.bounds_min + o.bounds_max);
    if (dim == 2) o.reference_point.z() = 0;
  }
  o.motion.kind = os.motion;
  o.motion.velocity = os.velocity;
  o.motion.angular_velocity = os.angular_velocity_deg * (std::numbers::pi / 180.0);
  o.motion.center = os.center ? *os.center : o.reference_point;
  o.motion.table = os.table;
  if (os.motion == ObstacleMotionKind::kDynamic) {
    // The state of a dynamic body is that of its reference point (obstacle.h RigidBodyState).
    o.motion.center = o.reference_point;
    o.motion.mass = os.mass;
    o.motion.density = os.density;
    o.motion.restitution = os.restitution;
  }
  // Faces on or beyond the domain boundary at t = 0 never act (a barrier standing on the floor,
  // a body spanning a slab between slip walls). For a moving obstacle this holds while it slides
  // along that wall (docs/scene-reference.md).
  o.buried_faces = BuriedFaces(o.shape, dim, spec.domain.min, spec.domain.max,
                               1e-9 * spec.grid.cell_size);
  return o;
}

SeededBody SeedBody(const SceneSpec& spec, size_t b, const std::vector<Obstacle>& obstacles) {
  const BodySpec& body = spec.bodies[b];
  const MaterialSpec& material = spec.materials[body.material_index];
  const int dim = spec.dimension;
  const std::string path = BodyPath(b);
  const Real s = spec.grid.cell_size / body.particles_per_cell;  // particle spacing [m]

  TriangleMesh mesh;
  const TriangleMesh* mesh_ptr = nullptr;
  if (const auto* region = std::get_if<MeshRegion>(&body.region)) {
    const std::string file_path = path + ".region.mesh.file";
    try {
      mesh = ReadTriangleMesh(region->file);
    } catch (const std::exception& e) {
      Fail(region->file_loc, file_path, e.what());
    }
    for (Vec3& v : mesh.vertices) v = region->scale * v + region->translate;
    const int open = CountOpenEdges(mesh);
    if (open > 0) {
      Fail(region->file_loc, file_path,
           "mesh '" + region->file + "' is not closed: " + std::to_string(open) +
               " edges are not shared by exactly two triangles (the inside test needs a "
               "watertight mesh)");
    }
    mesh_ptr = &mesh;
  }

  const double candidates = CountLatticePoints(RegionBounds(body.region, mesh_ptr), dim, s);
  if (candidates > kMaxCandidates) {
    Fail(body.region_loc, path + ".region",
         "the region spans about " + Num(std::round(candidates)) +
             " particle lattice points at spacing " + Num(s) +
             " m (limit 4e8); use a larger cell_size or fewer particles_per_cell");
  }

  SeededBody out;
  out.x = SampleRegion(body.region, dim, s, mesh_ptr);
  if (out.x.empty()) {
    Fail(body.region_loc, path + ".region",
         "the region contains no particles at spacing " + Num(s) +
             " m (cell_size / particles_per_cell); it may be thinner than one spacing");
  }
  JitterPositions(dim, s, body.jitter, body.seed, out.x);
  // Carve the obstacles out of the body: a region drawn through a column or below a terrain
  // mesh keeps only the particles outside every obstacle.
  if (!obstacles.empty()) {
    const size_t before = out.x.size();
    std::erase_if(out.x, [&](const Vec3& x) {
      for (const Obstacle& o : obstacles) {
        if (QueryObstacle(o, PoseAt(o, 0), x, dim, 0, spec.grid.cell_size).distance < 0) return true;
      }
      return false;
    });
    if (out.x.size() < before) {
      LogInfo("body '" + body.name + "': " + std::to_string(before - out.x.size()) +
              " particles inside obstacles were not seeded");
    }
    if (out.x.empty()) {
      Fail(body.region_loc, path + ".region",
           "every particle of body '" + body.name + "' lies inside an obstacle");
    }
  }

  for (const Vec3& x : out.x) {
    for (int a = 0; a < dim; ++a) {
      if (!(spec.domain.min[a] <= x[a] && x[a] <= spec.domain.max[a])) {
        Fail(body.region_loc, path + ".region",
             "body '" + body.name + "' has a particle at " + Point(x, dim) +
                 " outside the domain " + Point(spec.domain.min, dim) + " - " +
                 Point(spec.domain.max, dim));
      }
    }
  }

  out.volume0 = dim == 3 ? s * s * s : s * s * 1.0;  // 2-D plane strain: 1 m thickness
  out.mass = material.density * out.volume0;
  const size_t n = out.x.size();
  out.stress.assign(n, Mat3::Zero());
  out.ext_force.assign(n, Vec3::Zero());

  if (body.geostatic_k0) {
    // K0 geostatic state (Mast 2013 §7.4, eq. (7.17) uses the same K0 earth pressure;
    // spec/seed-algorithms.md "Initial stress" [REC]): sigma_v = -rho |g| d (compression
    // negative), sigma_h = K0 sigma_v, d = depth below the body's top surface along g.
    const Real g = spec.gravity.norm();
    const Vec3 ghat = spec.gravity / g;
    const Mat3 vertical = ghat * ghat.transpose();
    const Mat3 horizontal = Mat3::Identity() - vertical;
    Real h_top = -std::numeric_limits<Real>::infinity();
    for (const Vec3& x : out.x) h_top = std::max(h_top, -ghat.dot(x));
    h_top += 0.5 * s;  // the free surface lies half a spacing above the top particle layer
    for (size_t p = 0; p < n; ++p) {
      const Real depth = h_top + ghat.dot(out.x[p]);
      const Real sigma_v = -material.density * g * depth;
      out.stress[p] = sigma_v * vertical + (*body.geostatic_k0) * sigma_v * horizontal;
    }
  }

  // Tractions on the outermost particle layer of a face: f_p = t A_p with A_p = V_p / s
  // (Mast 2013 App. B.2.9, particle traction).
  const Real area = out.volume0 / s;
  for (const TractionSpec& t : body.tractions) {
    const int axis = static_cast<int>(t.face) / 2;
    const bool at_max = static_cast<int>(t.face) % 2 == 1;
    Real extreme = out.x[0][axis];
    for (const Vec3& x : out.x) extreme = at_max ? std::max(extreme, x[axis]) : std::min(extreme, x[axis]);
    for (size_t p = 0; p < n; ++p) {
      if (std::abs(out.x[p][axis] - extreme) <= 0.5 * s) out.ext_force[p] += t.traction * area;
    }
  }
  return out;
}

}  // namespace

void BuildScene(const SceneSpec& spec, Model& model, State& state) {
  model = Model{};
  model.name = spec.name;
  model.dim = spec.dimension;
  model.dx = spec.grid.cell_size;
  model.shape = spec.grid.shape_function;
  model.transfer = spec.grid.transfer;
  // alpha of v = alpha FLIP + (1 - alpha) PIC: pure FLIP, the given blend, or none for APIC.
  model.flip_ratio = spec.grid.transfer == TransferScheme::kFlip      ? 1.0
                     : spec.grid.transfer == TransferScheme::kPicFlip ? spec.grid.flip_ratio
                                                                      : 0.0;
  model.scheme = spec.grid.update;
  model.gravity = spec.gravity;
  model.gravity_ramp = spec.gravity_ramp;
  model.time.end = spec.time.end;
  model.time.cfl = spec.time.cfl;
  model.time.min_dt = spec.time.min_dt;
  model.time.max_dt = spec.time.max_dt;
  model.time.fixed_dt = spec.time.fixed_dt;
  model.domain_min = spec.domain.min;
  model.domain_max = spec.domain.max;
  model.walls = spec.domain.walls;
  model.exit_policy = spec.domain.on_exit;
  model.ghost_nodes = spec.domain.ghost_nodes;
  model.wall_gap_test = spec.domain.gap_test;
  for (const MaterialSpec& m : spec.materials) {
    model.materials.push_back(
        Material{m.name, m.density, FindMaterialKind(m.model).make_params(m), m.particle_shifting});
    model.antilocking.push_back(ResolvedAntiLocking(m));
    model.bulk_viscosity.push_back(m.bulk_viscosity);
    if (m.particle_shifting && model.shape != ShapeFunction::kQuadraticBspline) {
      Fail(m.loc, "materials." + m.name + ".particle_shifting",
           "particle shifting needs grid.shape_function: quadratic_bspline (its node volumes "
           "are the B-spline's integrals)");
    }
  }
  model.damping.alpha = spec.damping.local;
  if (spec.damping.until) model.damping.until = *spec.damping.until;
  if (spec.damping.equilibrium) {  // Anura3D §6.4
    model.damping.force_ratio = spec.damping.force_ratio;
    model.damping.energy_ratio = spec.damping.energy_ratio;
  }
  model.mass_scaling.factor = spec.mass_scaling.factor;
  if (spec.mass_scaling.until) model.mass_scaling.until = *spec.mass_scaling.until;
  for (const BodySpec& b : spec.bodies) {
    int antilocking = b.material_index;  // the material's setting
    if (b.antilocking) {                 // the body's own (docs/antilocking.md, "Per body")
      antilocking = static_cast<int>(model.antilocking.size());
      model.antilocking.push_back(ResolvedAntiLocking(spec, b));
    }
    model.bodies.push_back(BodyInfo{b.name, b.material_index, antilocking});
  }
  for (size_t o = 0; o < spec.obstacles.size(); ++o) model.obstacles.push_back(BuildObstacle(spec, o));
  for (const SensorSpec& s : spec.sensors) model.sensors.push_back(Sensor{s.name, s.min, s.max});
  // Body contacts: the bodies named in a pair get a velocity field each (in body order), all
  // other bodies share one more field (bonded to everything, as in single-field MPM).
  if (!spec.body_contacts.empty()) {
    std::vector<bool> paired(spec.bodies.size(), false);
    for (const BodyContactSpec& c : spec.body_contacts) {
      const int a = std::min(c.body_index[0], c.body_index[1]);
      const int b = std::max(c.body_index[0], c.body_index[1]);
      model.body_contacts.push_back(BodyContact{a, b, c.body_index[0], c.friction, c.separable,
                                                c.gap_test, c.bodies[1] + "_on_" + c.bodies[0]});
      paired[a] = paired[b] = true;
    }
    int fields = 0;
    model.body_field.assign(spec.bodies.size(), -1);
    for (size_t b = 0; b < spec.bodies.size(); ++b)
      if (paired[b]) model.body_field[b] = fields++;
    const bool rest = std::find(paired.begin(), paired.end(), false) != paired.end();
    for (size_t b = 0; b < spec.bodies.size(); ++b)
      if (!paired[b]) model.body_field[b] = fields;
    model.field_count = fields + (rest ? 1 : 0);
    if (model.field_count > kMaxVelocityFields) {
      Fail(spec.body_contacts.front().loc, "body_contact",
           "the body pairs need " + std::to_string(model.field_count) +
               " velocity fields; at most " + std::to_string(kMaxVelocityFields) + " are supported");
    }
  }
  model.output.every = spec.output.every;
  model.output.vdb = spec.output.vdb;
  model.output.energy = spec.output.energy;
  model.output.checkpoint_every = spec.output.checkpoint_every;
  model.output.checkpoints_keep = spec.output.checkpoints_keep;
  BuildAnalysis(spec, model);

  // Memory (issue 9): refuse a scene that cannot fit before seeding allocates anything. The
  // The optional particle arrays the materials and tractions need (Particles::layout).
  const bool tractions = std::any_of(spec.bodies.begin(), spec.bodies.end(),
                                     [](const BodySpec& b) { return !b.tractions.empty(); });
  const ParticleLayout layout = ParticleLayoutFor(model, tractions);
  const StepScratch scratch = StepScratchFor(model);
  // lattice points of each region's bounding box bound its particles from above (exactly for
  // boxes); mesh regions are counted after seeding, below.
  {
    double particles = 0;
    Aabb box{spec.domain.max, spec.domain.min};
    for (const BodySpec& b : spec.bodies) {
      if (std::holds_alternative<MeshRegion>(b.region)) continue;
      const Aabb r = RegionBounds(b.region, nullptr);
      const double c =
          CountLatticePoints(r, spec.dimension, spec.grid.cell_size / b.particles_per_cell);
      if (!(c <= kMaxCandidates)) continue;  // SeedBody refuses it with its own message
      particles += c;
      box.min = box.min.cwiseMin(r.min);
      box.max = box.max.cwiseMax(r.max);
    }
    if (particles > 0) {
      CheckMemory(spec, particles, box, model.field_count, layout, scratch, "at most ");
    }
  }

  // Seed every body; ids follow seeding order (body by body).
  std::vector<SeededBody> seeded;
  std::vector<int64_t> first_id;
  double total = 0;
  for (size_t b = 0; b < spec.bodies.size(); ++b) {
    first_id.push_back(static_cast<int64_t>(total));
    seeded.push_back(SeedBody(spec, b, model.obstacles));
    total += static_cast<double>(seeded.back().x.size());
    if (total > kMaxParticles) {
      Fail(spec.bodies[b].loc, BodyPath(b),
           "the scene has more than 2e8 particles (" + std::to_string(static_cast<long long>(total)) +
               " after body '" + spec.bodies[b].name + "')");
    }
  }

  {  // the exact count and bounding box before the particle arrays are allocated
    Aabb box{spec.domain.max, spec.domain.min};
    for (const SeededBody& s : seeded) {
      for (const Vec3& x : s.x) {
        box.min = box.min.cwiseMin(x);
        box.max = box.max.cwiseMax(x);
      }
    }
    CheckMemory(spec, total, box, model.field_count, layout, scratch, "");
  }

  // Lay the particles out grouped by material, then by anti-locking setting (the material's
  // first, then the bodies' own in file order), bodies in file order within a group: without
  // per-body settings the same order as a stable sort of the seeding order by material index.
  state = State{};
  for (Obstacle& o : model.obstacles) {  // dynamic bodies start at their reference pose
    if (o.motion.kind != ObstacleMotionKind::kDynamic) continue;
    o.motion.body = static_cast<int>(state.rigid.size());
    state.rigid.push_back(RigidBodyState{o.motion.center, Mat3::Identity(), o.motion.velocity,
                                         o.motion.angular_velocity});
  }
  Particles& P = state.particles;
  P.layout = layout;
  P.Resize(static_cast<size_t>(total));
  SymMat3 unused_b;  // InitialHistory's output for a layout without b^e
  size_t next = 0;
  std::vector<std::pair<int, int>> keys;  // (material, anti-locking setting) in layout order
  for (const BodyInfo& b : model.bodies) keys.emplace_back(b.material, b.antilocking);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  for (const auto& [m, setting] : keys) {
    const size_t begin = next;
    for (size_t b = 0; b < spec.bodies.size(); ++b) {
      if (model.bodies[b].material != m || model.bodies[b].antilocking != setting) continue;
      const SeededBody& s = seeded[b];
      for (size_t k = 0; k < s.x.size(); ++k, ++next) {
        P.x[next] = s.x[k];
        P.v[next] = spec.bodies[b].velocity;
        if (P.layout.affine) P.C[next] = Mat3::Zero();
        P.F[next] = Mat3::Identity();
        P.stress[next] = s.stress[k];
        if (P.layout.strain) P.strain[next] = Mat3::Zero();
        History history;
        InitialHistory(model.materials[size_t(m)], s.stress[k],
                       P.layout.elastic_b ? P.elastic_b[next] : unused_b, history);
        if (P.layout.history) P.history.Set(next, history);
        P.mass[next] = s.mass;
        P.volume0[next] = s.volume0;
        if (P.layout.ext_force) P.ext_force[next] = s.ext_force[k];
        P.material[next] = static_cast<int32_t>(m);
        P.body[next] = static_cast<int32_t>(b);
        P.id[next] = first_id[b] + static_cast<int64_t>(k);
      }
    }
    if (next > begin) state.groups.push_back(MaterialGroup{m, begin, next, setting});
  }
}

// --- analysis defaults (docs/scene-reference.md, `analysis`) -------------------------------

namespace {

// Index of the coordinate axis g points along, or -1 when g is zero or not axis-aligned.
int GravityAxis(const Vec3& g) {
  for (int a = 0; a < 3; ++a) {
    if (g[a] != 0 && g[(a + 1) % 3] == 0 && g[(a + 2) % 3] == 0) return a;
  }
  return -1;
}

}  // namespace

ResolvedAnalysis ResolveAnalysis(const SceneSpec& spec, const AnalysisSettings& written) {
  ResolvedAnalysis out;
  AnalysisSettings& s = out.settings;
  s = written;
  std::string& source = out.reference_source;
  const auto note = [&](const std::string& what) { source += (source.empty() ? "" : "; ") + what; };
  if (s.structure.empty()) {
    s.structure = !spec.obstacles.empty() ? spec.obstacles.front().name
                  : !spec.sensors.empty() ? spec.sensors.front().name
                                          : "domain";
  }
  ReferenceValues& r = s.reference;
  const BodySpec* body = spec.bodies.empty() ? nullptr : &spec.bodies.front();
  if (!r.density && body) {
    const MaterialSpec& m = spec.materials.at(size_t(body->material_index));
    r.density = m.density;
    note("density: materials." + m.name + ".density");
  }
  if (!r.gravity && spec.gravity.norm() > 0) {
    r.gravity = spec.gravity.norm();
    note("gravity: |gravity|");
  }
  if (!r.velocity && body && body->velocity.norm() > 0) {
    r.velocity = body->velocity.norm();
    note("velocity: |bodies[0].velocity|");
  }
  if (!r.k0 && body && body->geostatic_k0) {
    r.k0 = *body->geostatic_k0;
    note("k0: bodies[0].initial_stress.geostatic.k0");
  }
  const int g_axis = GravityAxis(spec.gravity);
  if (!r.width) {
    if (spec.dimension == 2) {
      r.width = 1.0;  // 2-D forces and areas are per metre of thickness
      note("width: 1 m (2-D, per metre)");
    } else if (const auto n_face = s.face.size() == 2 && g_axis >= 0 ? s.face[0] - 'x' : -1;
               n_face >= 0 && n_face < 3 && n_face != g_axis) {
      for (const ObstacleSpec& o : spec.obstacles) {
        const BoxRegion* box = std::get_if<BoxRegion>(&o.shape);
        if (o.name != s.structure || !box) continue;
        const int across = 3 - n_face - g_axis;  // the axis normal to both the face and gravity
        // The part inside the domain: a column sunk through a side wall is exposed only there.
        r.width = std::min(box->max[across], spec.domain.max[across]) -
                  std::max(box->min[across], spec.domain.min[across]);
        note("width: obstacle '" + o.name + "' box extent along " + std::string(1, char('x' + across)) +
             " inside the domain");
      }
    }
  }
  if (!r.height && body && g_axis >= 0) {
    if (const BoxRegion* box = std::get_if<BoxRegion>(&body->region)) {
      r.height = std::min(box->max[g_axis], spec.domain.max[g_axis]) -
                 std::max(box->min[g_axis], spec.domain.min[g_axis]);
      note("height: bodies[0] box extent along gravity");
    }
  }
  return out;
}

}  // namespace surge

// Scene spec: plain structs mirroring the scene file (docs/scene-reference.md), with every default
// written here. scene_parser.cpp fills and validates them; scene_builder.cpp turns them into
// Model + State. Positions carry the source location the builder needs for its own errors.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "core/analysis.h"
#include "core/math.h"
#include "core/model.h"
#include "materials/material_params.h"

namespace surge {

// Where a value came from: a file position (1-based) or a --set override (`source`).
struct SourceLoc {
  std::string source;  // file name, "<string>" or "--set key=value"
  int line = 0;
  int column = 0;
};

struct TimeSpec {
  Real end = 0;         // required, > 0 [s]
  Real cfl = 0.4;       // (0, 1] [-]
  Real min_dt = 1e-12;  // >= 0 [s]
  Real max_dt = 1e30;   // > 0 [s] (1e30 = unbounded)
  Real fixed_dt = 0;    // >= 0 [s]; 0 = adaptive (CFL)
};

struct GridSpec {
  Real cell_size = 0;  // required, > 0 [m]
  ShapeFunction shape_function = ShapeFunction::kQuadraticBspline;
  TransferScheme transfer = TransferScheme::kApic;
  Real flip_ratio = 0.95;  // [0, 1]; only with transfer pic_flip
  UpdateScheme update = UpdateScheme::kUsl;
};

struct DomainSpec {
  Vec3 min = Vec3::Zero();            // required [m]
  Vec3 max = Vec3::Zero();            // required [m], > min in each seeded component
  std::array<Wall, kFaceCount> walls; // missing faces are open
  ExitPolicy on_exit = ExitPolicy::kRemove;
  GhostNodes ghost_nodes = GhostNodes::kMirror;  // mirror (default) | mirror_velocity | constrain
  bool gap_test = true;               // gap_test: true (default) | false
};

// Material models known to the scene file; names and constructors live in the one table in
// material_kinds.cpp (MaterialKinds()).
enum class MaterialModel {
  kLinearElastic,
  kNeoHookean,
  kJ2,
  kNewtonianFluid,
  kBinghamFluid,
  kFrictionalFluid,
  kSnow,
  kMatsuokaNakai,
  kMatsuokaNakaiDp,
  kMohrCoulomb,
  kTresca,
  kModifiedDruckerPrager,
  kSmoothCapDruckerPrager,
  kDruckerPrager,
};

// `antilocking: {method, approach, fit, strain, stress}` of a material or a body
// (docs/antilocking.md).
struct AntiLockingSpec {
  std::optional<AntiLockingMethod> method;  // unset: the default of the material's class
  AntiLockingApproach approach = AntiLockingApproach::kVolumetric;
  AntiLockingStrain strain = AntiLockingStrain::kTotal;
  bool stress = false;  // `stress: true`: Table 4.1 steps 6-7
  bool constant_fit = false;  // `fit: constant`: the seed's ConstantAntiLocking
  bool linear_trace = false;  // `fit: linear` with method node, approach volumetric
};

struct MaterialSpec {
  std::string name;  // the key under `materials`
  MaterialModel model = MaterialModel::kLinearElastic;
  Real density = 0;  // [kg/m^3]
  // Elasticity of the models whose kind has `elastic` set is given either as (K, G) or as
  // (E, nu); the parser fills K and G in both cases.
  bool given_as_youngs = false;
  Real bulk_modulus = 0;   // K [Pa]
  Real shear_modulus = 0;  // G [Pa]
  Real youngs_modulus = 0; // E [Pa] (given_as_youngs only)
  Real poisson_ratio = 0;  // nu [-] (given_as_youngs only)
  // The model's own keys (MaterialKind::params) as written in the file; an enumerated key holds
  // the index of its choice. Keys not written take their default through Param().
  std::map<std::string, Real, std::less<>> values;
  // `antilocking` (docs/antilocking.md); method unset = the default of the material's class,
  // ResolvedAntiLocking(). A body may override it (BodySpec::antilocking).
  AntiLockingSpec antilocking;
  // `bulk_viscosity: {quadratic, linear}` (docs/antilocking.md); disabled when not written.
  BulkViscosity bulk_viscosity;
  // `particle_shifting: true` (docs/antilocking.md, "Particle shifting"); off when not written.
  bool particle_shifting = false;
  SourceLoc loc;

  // Value of a model key: as written, else the kind's default. Pre: `key` is one of the kind's.
  Real Param(std::string_view key) const;
};

// One model-specific key of a material (docs/scene-reference.md): a number in a range, or (when
// `choices` is non-empty) one of a list of names, stored as its index.
struct ParamDesc {
  const char* key;
  const char* unit;  // shown in messages: "Pa", "deg", "-", ...
  Real min = 0;
  bool min_open = false;  // min itself is not allowed
  Real max = std::numeric_limits<Real>::infinity();
  bool max_open = false;
  bool required = false;
  Real default_value = 0;  // when not required and not written
  std::span<const char* const> choices = {};
};

// A cross-key rule a kind's `check` found broken: the key to point at, and why.
struct ParamError {
  std::string key;
  std::string message;
};

// Kinds of material model: one table (material_kinds.cpp) used by parser, writer and builder.
// A new model adds a MaterialModel value, a params struct in materials/material_params.h and a
// row in that table.
struct MaterialKind {
  const char* name;  // value of `model:` in the scene file
  MaterialModel model;
  bool allows_geostatic;  // the initial stress can be prescribed (not derived from F)
  bool elastic;           // takes the elastic pair (K, G) or (E, nu)
  std::span<const ParamDesc> params;
  MaterialParams (*make_params)(const MaterialSpec&);
  std::optional<ParamError> (*check)(const MaterialSpec&) = nullptr;  // cross-key rules
  // Friction angle [deg] used by `k0: jaky` (geostatic start); nullptr: the model has none.
  Real (*friction_angle_deg)(const MaterialSpec&) = nullptr;
};
std::span<const MaterialKind> MaterialKinds();
const MaterialKind& FindMaterialKind(MaterialModel model);

struct BoxRegion {
  Vec3 min = Vec3::Zero();  // [m]
  Vec3 max = Vec3::Zero();  // [m]
};
struct SphereRegion {  // a disk in 2-D
  Vec3 center = Vec3::Zero();  // [m]
  Real radius = 0;             // [m]
};
struct CylinderRegion {  // 3-D only
  Vec3 base = Vec3::Zero();  // centre of the base disk [m]
  Vec3 top = Vec3::Zero();   // centre of the top disk [m]
  Real radius = 0;           // [m]
};
struct PolygonRegion {  // simple polygon in the xy plane, extruded over [z0, z1] in 3-D
  std::vector<std::array<Real, 2>> points;  // [m]
  Real z0 = 0;                              // [m] (3-D only)
  Real z1 = 0;                              // [m] (3-D only)
};
struct MeshRegion {  // 3-D only: the inside of a closed triangle mesh
  std::string file;   // resolved path (relative paths are taken from the scene file's directory)
  std::string file_hash;  // FNV-1a of the file's bytes (core/hash.h); "" when it cannot be read
  Real scale = 1;     // vertices are scaled, then translated [-]
  Vec3 translate = Vec3::Zero();  // [m]
  SourceLoc file_loc;
};
using RegionShape = std::variant<BoxRegion, SphereRegion, CylinderRegion, PolygonRegion, MeshRegion>;

struct TractionSpec {
  Face face = Face::kXMax;
  Vec3 traction = Vec3::Zero();  // [Pa]
};

struct BodySpec {
  std::string name;
  std::string material;    // name, as written
  int material_index = 0;  // into SceneSpec::materials
  RegionShape region;
  int particles_per_cell = 2;  // per direction, 1..8
  Real jitter = 0;             // [0, 1) of a particle spacing
  uint64_t seed = 1;           // jitter RNG seed
  Vec3 velocity = Vec3::Zero();  // [m/s]
  std::optional<Real> geostatic_k0;  // initial_stress: {geostatic: {k0}}
  bool k0_from_friction = false;     // k0 was given as `jaky`: 1 - sin(phi) of the material
  std::vector<TractionSpec> tractions;
  // `antilocking`: this body's own setting, replacing its material's (written in full, method
  // required); unset: the material's (docs/antilocking.md, "Per body").
  std::optional<AntiLockingSpec> antilocking;
  SourceLoc loc;         // the body's map
  SourceLoc region_loc;  // the `region` map
};

// Obstacles (issue #5; docs/scene-reference.md `obstacles`). Box, sphere, cylinder and polygon
// reuse the region shapes; a plane and a mesh have their own.
struct ObstacleMeshSpec {
  std::string file;                 // resolved path (as MeshRegion)
  std::string file_hash;            // as MeshRegion
  Real scale = 1;                   // [-]
  Vec3 rotate_deg = Vec3::Zero();   // rotations about x, then y, then z [deg]
  Vec3 translate = Vec3::Zero();    // [m], applied last
  bool one_sided = false;           // an open mesh: its triangle normals point to the outside
  bool faces_by_normal = false;     // faces: normal: triangles grouped as x-, x+, y-, y+, z-, z+
                                    // by their normal's dominant axis (default: mesh parts)
  SourceLoc file_loc;
};
using ObstacleShapeSpec =
    std::variant<PlaneShape, BoxRegion, SphereRegion, CylinderRegion, PolygonRegion, ObstacleMeshSpec>;

struct ObstacleSpec {
  std::string name;
  ObstacleShapeSpec shape;
  ObstacleMotionKind motion = ObstacleMotionKind::kFixed;
  Vec3 velocity = Vec3::Zero();              // prescribed, or dynamic initial [m/s]
  Vec3 angular_velocity_deg = Vec3::Zero();  // prescribed, or dynamic initial [deg/s]
  Real mass = 0;                             // dynamic: [kg] (or density)
  Real density = 0;                          // dynamic: [kg/m^3] (or mass)
  Real restitution = 0;                      // dynamic: Bullet collisions [-]
  std::optional<Vec3> center;                // centre of rotation; default: reference point
  std::vector<std::array<Real, 4>> table;    // prescribed by a table: {t, dx, dy, dz} rows
  ObstacleContact contact;
  std::optional<Vec3> reference_point;       // torque reference; default: centre of the bounds
  SourceLoc loc;
  SourceLoc shape_loc;
};

struct SensorSpec {  // a force sensor box (contact/obstacle.h Sensor)
  std::string name;
  Vec3 min = Vec3::Zero();  // [m]
  Vec3 max = Vec3::Zero();  // [m]
  SourceLoc loc;
};

struct BodyContactSpec {  // a pair of bodies in frictional contact (core/model.h BodyContact)
  std::array<std::string, 2> bodies;
  std::array<int, 2> body_index{};  // into SceneSpec::bodies
  Real friction = 0;                // [-]
  bool separable = true;
  bool gap_test = true;             // default: separable
  SourceLoc loc;
};

struct OutputSpec {
  Real every = 0;  // [s]; 0 = first and last only
  bool vdb = false;
  bool energy = true;
  Real checkpoint_every = 0;  // [s] of simulated time; 0 = no periodic checkpoints
  int checkpoints_keep = 3;   // newest periodic checkpoints kept
};

// `analysis:` (docs/scene-reference.md): what `surge forces` and the end of `surge run` analyse.
// `settings` holds the values as written (unset reference values stay unset); ResolveAnalysis
// fills the defaults.
struct AnalysisSpec {
  bool present = false;  // the scene has an `analysis` section
  AnalysisSettings settings;
  SourceLoc loc, structure_loc, face_loc;
};

// `damping:` (docs/scene-reference.md): Cundall local damping (core/model.h LocalDamping).
struct DampingSpec {
  Real local = 0;              // alpha [-], [0, 1); 0 = off
  std::optional<Real> until;   // [s]; unset = the whole run
  // `equilibrium: {force_ratio, energy_ratio}`: release at static equilibrium (Anura3D §6.4).
  bool equilibrium = false;
  Real force_ratio = 1e-3, energy_ratio = 1e-4;  // tolerances of (6.29), (6.30) [-]
  SourceLoc loc;
};

// `mass_scaling:` (docs/scene-reference.md): Anura3D mass scaling (core/model.h MassScaling).
struct MassScalingSpec {
  Real factor = 1;             // beta [-], >= 1; 1 = off
  std::optional<Real> until;   // [s]; unset = the whole run
  SourceLoc loc;
};

struct SceneSpec {
  std::string name;
  int dimension = 3;
  TimeSpec time;
  Vec3 gravity = Vec3::Zero();  // [m/s^2]
  Real gravity_ramp = 0;        // [s]
  DampingSpec damping;
  MassScalingSpec mass_scaling;
  GridSpec grid;
  DomainSpec domain;
  std::vector<MaterialSpec> materials;  // in file order; Model::materials has the same order
  std::vector<BodySpec> bodies;
  std::vector<ObstacleSpec> obstacles;  // in file order; Model::obstacles has the same order
  std::vector<SensorSpec> sensors;      // in file order; Model::sensors has the same order
  std::vector<BodyContactSpec> body_contacts;  // in file order (Model::body_contacts)
  OutputSpec output;
  AnalysisSpec analysis;
  // `parameters:` in file order, after --set overrides; `${expr}` values were evaluated over
  // them before validation (scene_expressions.h).
  std::vector<std::pair<std::string, Real>> parameters;
};

// Parses scene text into a validated spec. `source` names the text in errors; `base_dir` resolves
// relative asset paths; `overrides` are "key.path=value" strings applied before validation.
// Throws SceneError.
SceneSpec ParseSceneSpec(const std::string& text, const std::string& source,
                         const std::string& base_dir, const std::vector<std::string>& overrides);

// Anti-locking of a material: as written, else node-based volumetric on the total strain for the
// Newtonian fluid (smooth pressure and wall forces, seed §3.7) and none for every other model.
AntiLocking ResolvedAntiLocking(const MaterialSpec& m);
// Anti-locking of a body: its own setting when it has one, else its material's.
AntiLocking ResolvedAntiLocking(const SceneSpec& spec, const BodySpec& b);

// The analysis settings of a scene with the defaults filled in (docs/scene-reference.md,
// `analysis`): `written` is spec.analysis.settings, possibly changed by the caller (the options
// of `surge forces`). Structure: the first obstacle, else sensor, else "domain". Reference
// values not written: density of the first body's material, |gravity|, |velocity| of the first
// body (if not 0), k0 of its geostatic start, width 1 in 2-D (per metre) or, for an axis face of
// a box obstacle with gravity along an axis, the box's extent across both, height the first
// body's box extent along gravity. `reference_source` says where each default came from.
struct ResolvedAnalysis {
  AnalysisSettings settings;
  std::string reference_source;  // e.g. "density: materials.sand; velocity: bodies[0].velocity"
};
ResolvedAnalysis ResolveAnalysis(const SceneSpec& spec, const AnalysisSettings& written);

// The spec as YAML with every default written out; ParseSceneSpec reads it back to an equal spec.
std::string SceneSpecToYaml(const SceneSpec& spec);

}  // namespace surge

// Model: everything read-only during a run (STYLE H.4): grid, time control, gravity, materials,
// domain walls, output plan. Built once from a scene by scene_builder.cpp.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "contact/obstacle.h"
#include "core/analysis.h"
#include "core/math.h"
#include "materials/material_params.h"

namespace surge {

enum class ShapeFunction { kLinear, kGimp, kQuadraticBspline, kCubicBspline };
enum class TransferScheme { kFlip, kPicFlip, kApic };
enum class UpdateScheme { kUsl, kMusl };

// Domain faces, in the order of Model::walls.
enum class Face { kXMin = 0, kXMax, kYMin, kYMax, kZMin, kZMax };
inline constexpr int kFaceCount = 6;
const char* FaceName(Face f);  // "x-", "x+", ...

// Nodes beyond a domain wall ("ghost nodes", reached by the quadratic and cubic B-splines;
// MirrorGhostNodes, docs/walls.md), scene key domain.ghost_nodes.
enum class GhostNodes {
  kConstrain,       // `constrain`: each ghost is constrained like the node on the wall
  kMirrorVelocity,  // `mirror_velocity`: the ghost's normal v_{n+1} is set to minus its mirror's
  kMirror,          // `mirror` (default): the ghost's momentum and mass are folded into its mirror
                    // node (the odd extension in the Galerkin sense), then the ghost takes minus
                    // the mirror's velocity; no-slip walls fold every component. Bilateral walls
                    // only; separable and friction walls get the velocity mirror
  kFoldAll,         // `fold_all`: as kMirror, and separable frictionless walls fold too where the
                    // material presses on them (opt-in: removes the wall drag of flow along a
                    // wall, but offsets node AS1's pressure; with the linear node fit it is the
                    // settle recipe; folding walls fewer than 3 cells apart tilt a floating box;
                    // docs/walls.md)
};

enum class WallKind {
  kOpen,     // no wall: particles leaving are removed or stop the run (Model::exit_policy)
  kSlip,     // v.n >= 0 (separable) or v.n = 0 (bilateral); tangential free (seed Planar)
  kNoSlip,   // v = 0 at wall nodes (seed Fixed)
  kFriction  // Coulomb friction with coefficient `friction` (seed Planar with mu > 0)
};

struct Wall {
  WallKind kind = WallKind::kOpen;
  Real friction = 0;     // Coulomb coefficient [-] (kFriction only)
  bool separable = true; // true: the wall only pushes (tension release); false: bilateral
};

enum class ExitPolicy { kRemove, kStop };

// Anti-locking of a material (Mast 2013 ch. 4; src/stabilize): the control volumes (4.25)-(4.35).
// kHybrid: the trace from node-based control volumes, the deviator from cell-based ones (§4.4.3).
// kSmoothing: Anura3D's strain smoothing (nodal mixed discretisation, manual §6.7, (6.34)-(6.37)):
// cell values of the volumetric strain averaged to the nodes and back to the cells.
enum class AntiLockingMethod { kNone, kNode, kCell, kHybrid, kSmoothing };
// What is approximated (seed (4.14)-(4.23)): kVolumetric = AS1, the trace only, constant over the
// control volume; kVolumetricDeviatoric = AS2, the full tensor: trace, e11, e22 linear in the
// control volume, the shears constant; kConstantVolumetric = AS3CV, AS2 with a constant trace.
enum class AntiLockingApproach { kVolumetric, kVolumetricDeviatoric, kConstantVolumetric };
// What is projected: the trace of the total trial (elastic) Hencky strain, ln J^tr (seed §4.4.4),
// or only that of the step's increment, ln det f (F-bar on the increment).
enum class AntiLockingStrain { kTotal, kIncrement };
struct AntiLocking {
  AntiLockingMethod method = AntiLockingMethod::kNone;
  AntiLockingApproach approach = AntiLockingApproach::kVolumetric;
  AntiLockingStrain strain = AntiLockingStrain::kTotal;
  // Also project the mean stress after the stress update (seed Table 4.1 steps 6-7, optional).
  bool stress = false;
  // Full-tensor approaches: every filtered component constant over the control volume, the
  // seed's `ConstantAntiLocking AS2` ("does not utilize the diagonal terms in shape matrix",
  // spec §3.3), instead of its `TriLinearAntiLocking` (S rows [1, xi, eta, zeta]). AS1 is constant
  // either way.
  bool constant_fit = false;
  // Node-based AS1 with `fit: linear`: each node's theta is its support's weighted least-squares
  // linear fit evaluated at the node (the full-tensor node fit of the trace alone) instead of the
  // support's mean, which is the value at the support's centroid, half a cell inside a wall or a
  // free surface (docs/antilocking.md, "Linear node fit").
  bool linear_trace = false;
};

// Cundall's local non-viscous damping of the grid momentum balance (Anura3D manual §6.3.1, eqs.
// (6.22)-(6.23); docs/antilocking.md "Local damping"): f_damp = -alpha |f| sign(v) per component of
// every node, f = f_ext - f_int the unbalanced force. One alpha for the whole grid, as the manual
// gives one per degree of freedom; active for t < until (quasi-static initialisation, §6.4).
// Mass scaling for quasi-static phases (Anura3D manual §6.5, (6.31)): the density in the momentum
// balance is beta rho (the nodal inertia is scaled by beta; the weight, the internal and the
// external forces are not), so the critical time step grows by sqrt(beta). Active for t < until;
// the manual warns that a large beta changes the result: use it to settle a body, then let go.
struct MassScaling {
  Real factor = 1;      // beta >= 1 [-]; 1 = off
  Real until = 1e300;   // scaling acts while t_n < until [s]; default: the whole run
  Real At(Real t) const { return t < until ? factor : 1; }
};

struct LocalDamping {
  Real alpha = 0;        // local damping factor [-], 0 <= alpha < 1; 0 = off
  Real until = 1e300;    // damping acts while t_n < until [s]; default: the whole run
  // Release at static equilibrium (Anura3D manual §6.4): damping switches off after the first
  // step, once the load ramp is complete, at which the force ratio (6.29) and the energy ratio
  // (6.30) are both below these tolerances (State::damping_released); 0 = the `until` time alone.
  Real force_ratio = 0;   // tolerance of ||F_ext - F_int|| / ||F_ext|| [-]
  Real energy_ratio = 0;  // tolerance of KE / W_ext [-]
  // The factor at time t: alpha before `until`, 0 after.
  Real At(Real t) const { return t < until ? alpha : 0; }
  bool Equilibrium() const { return force_ratio > 0; }
};

// Artificial bulk viscosity of a material for shocks (von Neumann & Richtmyer 1950, J. Appl.
// Phys. 21:232; Wilkins 1980, J. Comput. Phys. 36:281; LS-DYNA Theory Manual, "Bulk viscosity"):
// q = rho l (c0 l (tr d)^2 - c1 c tr d) when tr d < 0, else 0, with l = dx and c the elastic wave
// speed; added to the pressure of the internal force only (src/stabilize/bulk_viscosity.cpp).
struct BulkViscosity {
  bool enabled = false;
  Real quadratic = 1.5;  // c0 [-] (LS-DYNA default Q1 = 1.5)
  Real linear = 0.06;    // c1 [-] (LS-DYNA default Q2 = 0.06)
};

struct TimeControl {
  Real end = 0;        // simulated end time [s]
  Real cfl = 0.4;      // Courant number C in dt = C dx / max(c + |v|) (spec §1.7)
  Real min_dt = 0;     // below this the run stops with a diagnostic [s]
  Real max_dt = 1e30;  // upper bound [s]
  Real fixed_dt = 0;   // > 0: use this dt every step (seed reproduction runs) [s]
};

struct BodyInfo {
  std::string name;
  int material = 0;
  int antilocking = 0;  // index into Model::antilocking: its material's, or its own override
};

// Frictional contact between two MPM bodies (scene key `body_contact`): each body listed in a
// pair moves with its own velocity field on the shared grid where bodies meet (Bardenhagen et
// al. 2000; Anura3D manual §6.2). Bodies in no pair share one field (single-field MPM: bonded).
inline constexpr int kMaxVelocityFields = 16;  // per-body velocity fields at most
struct BodyContact {
  int body_a = 0, body_b = 0;  // indices into Model::bodies, body_a < body_b
  int normal_body = 0;         // body_a or body_b: the body whose surface gives the normal
  Real friction = 0;           // Coulomb coefficient mu [-]
  bool separable = true;       // false: the bodies never separate (normal velocity bonded)
  // Speculative gap test (separable pairs): at a node the fields may still approach by the gap
  // between the two bodies' particles (body_contact.cpp); false: contact wherever both have mass.
  bool gap_test = true;
  std::string name;            // force-log channel: "<other>_on_<normal body>", the force on the
                               // normal body (listed first in the scene) from the other
};

struct OutputPlan {
  Real every = 0;          // particle snapshot interval [s]; 0 = first and last only
  bool vdb = false;        // also write grid fields (mass, velocity) as .vdb per snapshot
  bool energy = true;      // energy series every step
  // Checkpoints (<out>/checkpoints/<name>_step_<step>.h5, docs/results-format.md): written every
  // checkpoint_every [s] of simulated time (0 = only on Ctrl-C); the newest checkpoints_keep kept.
  Real checkpoint_every = 0;
  int checkpoints_keep = 3;
};

struct Model {
  std::string name;
  int dim = 3;                     // 2 = plane strain in the z = 0 slab, 3 = full 3-D
  Real dx = 0;                     // grid cell size [m]
  ShapeFunction shape = ShapeFunction::kQuadraticBspline;
  TransferScheme transfer = TransferScheme::kApic;
  Real flip_ratio = 1.0;           // alpha in v = alpha*FLIP + (1-alpha)*PIC (kPicFlip)
  UpdateScheme scheme = UpdateScheme::kUsl;
  Vec3 gravity = Vec3::Zero();     // [m/s^2]
  Real gravity_ramp = 0;           // external loads scaled by min(t/ramp, 1) (seed App. B.2.3) [s]
  TimeControl time;
  Vec3 domain_min = Vec3::Zero();  // [m]
  Vec3 domain_max = Vec3::Zero();  // [m]
  std::array<Wall, kFaceCount> walls;
  // Ghost nodes (nodes beyond a wall) take the mirror image of the normal velocity inside, so
  // the interpolated normal velocity vanishes on the wall plane (MirrorGhostNodes, scene key
  // domain.ghost_nodes: mirror, the default, or mirror_velocity); `constrain`: each ghost node is
  // constrained like a node on the wall (the normal inflow removed).
  GhostNodes ghost_nodes = GhostNodes::kMirror;
  // Gap test at domain walls (RebuildGrid, WallTouchMarker; scene key domain.gap_test): a wall
  // acts at a node only where a particle touches the wall in that node's column (its centre
  // within 1.5 of its half-size of the plane); false: wherever a node on or beyond the wall has
  // mass.
  bool wall_gap_test = true;
  ExitPolicy exit_policy = ExitPolicy::kRemove;
  std::vector<Material> materials;
  // One per material (index as materials), then one per body that overrides its material's
  // (BodyInfo::antilocking, MaterialGroup::antilocking); empty = none.
  std::vector<AntiLocking> antilocking;
  std::vector<BulkViscosity> bulk_viscosity;  // per material (index as materials); empty = none
  LocalDamping damping;                  // scene key `damping` (off by default)
  MassScaling mass_scaling;              // scene key `mass_scaling` (off by default)
  std::vector<BodyInfo> bodies;
  std::vector<Obstacle> obstacles;       // rigid structures (src/contact), in scene order
  std::vector<Sensor> sensors;           // force sensors (src/contact), in scene order
  std::vector<BodyContact> body_contacts;  // MPM-MPM contact pairs; empty = one velocity field
  // Velocity field of each body (index as bodies) when body_contacts is not empty: the bodies
  // named in a pair get fields 0, 1, ... in body order, all others share the last field.
  std::vector<int> body_field;
  int field_count = 0;                   // number of velocity fields; 0 = single-field MPM
  OutputPlan output;
  AnalysisSettings analysis;  // force analysis, defaults filled in (scene `analysis`, issue #6)
};

// Load factor of the external-force ramp at time t (seed App. B.2.3 ExternalForceRamp).
inline Real RampFactor(const Model& m, Real t) {
  return m.gravity_ramp > 0 && t < m.gravity_ramp ? t / m.gravity_ramp : 1.0;
}

}  // namespace surge

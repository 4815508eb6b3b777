// Stage adapters and the small stages owned by the step library: domain exit, health check
// and energy balance (STYLE H.7; DESIGN §4 items 7-8).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/end_checks.h"
#include "core/parallel.h"
#include "materials/update_stress.h"
#include "step/stages.h"

namespace surge {

void RebuildGridStage(const Model& m, const StepContext&, State& s, Workspace& w, StepReport&) {
  RebuildGrid(m, s.particles, w.grid);
}

void ParticleToGridStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                         StepReport&) {
  ParticleToGrid(m, c, s.particles, w.grid);
  if (c.mass_scale != 1) {
    // Mass scaling (Anura3D manual §6.5): the nodal inertia beta m_i and momentum beta m_i v_i
    // (the velocity v_i is unchanged); every later stage that turns a velocity change into a
    // force (walls, obstacles, sensors, damping) then logs the force on the scaled inertia, the
    // one that balances the unscaled loads. Gravity is g / beta (Step).
    const Real beta = c.mass_scale;
    ParallelFor(w.grid.mass.size(), 4096, [&](size_t i) {
      w.grid.mass[i] *= beta;
      w.grid.momentum[i] *= beta;
    });
    // The per-body fields of body contacts likewise (their forces are forces; the mass moment
    // scales with the mass, so the contact normals x-bar - x_i are unchanged).
    ParallelFor(w.grid.field_mass.size(), 4096, [&](size_t i) {
      w.grid.field_mass[i] *= beta;
      w.grid.field_momentum[i] *= beta;
      w.grid.field_mass_moment[i] *= beta;
    });
  }
}

void GridUpdateStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                     StepReport& r) {
  UpdateGridVelocity(m, c, w.grid, r.walls);
  s.wall_work += r.walls.work;
}

// After the obstacles, so that a ghost node mirrors the final velocity inside the domain.
void WallGhostStage(const Model& m, const StepContext& c, State& s, Workspace& w, StepReport& r) {
  const Real work = r.walls.work;
  MirrorGhostNodes(m, c, w.grid, true, &r.walls);
  s.wall_work += r.walls.work - work;
}

void ObstacleContactStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                          StepReport& r) {
  ApplyObstacleContact(m, c, s.rigid, w.grid, w.contact, &r.obstacles, &s.particles);
}

void BodyContactStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                      StepReport& r) {
  const bool gap_test = std::any_of(m.body_contacts.begin(), m.body_contacts.end(),
                                    [](const BodyContact& bc) { return bc.gap_test; });
  if (gap_test) ComputeBodyContactGaps(m, c, w.grid, s.particles, w.body_gaps);
  ApplyBodyContact(m, c, w.grid, r.walls, r.body_contact, gap_test ? &w.body_gaps : nullptr);
}

// Local damping (6.22)-(6.23) and, with the equilibrium rule (Anura3D manual §6.4), its release:
// once the load ramp is complete, the first step whose force ratio F = ||F_ext - F_int|| /
// ||F_ext|| (6.29) and energy ratio E = KE / W_ext (6.30) are both below the tolerances switches
// the damping off for the steps after it. KE is that of the particles at the start of the step
// (v_n); W_ext, the work of the (ramped) gravity on the particles, is summed as dt sum m g . v_n
// over every step while the rule watches, from the first one.
void LocalDampingStage(const Model& m, const StepContext& c, State& s, Workspace& w, StepReport& r) {
  if (c.damping <= 0) return;
  if (!m.damping.Equilibrium()) {
    ApplyLocalDamping(c, w.grid);
    return;
  }
  ApplyLocalDamping(c, w.grid, &w.damping);
  const Particles& P = s.particles;
  const Vec3 g = c.ramp * m.gravity;  // the weight's acceleration (unscaled by mass scaling)
  std::array<Real, kReductionChunks> kinetic{}, power{};
  ParallelChunks(P.size(), [&](size_t chunk, size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) {
      kinetic[chunk] += 0.5 * P.mass[p] * P.v[p].squaredNorm();
      power[chunk] += P.mass[p] * g.dot(P.v[p]);
    }
  });
  Real ke = 0, pw = 0;
  for (size_t k = 0; k < kReductionChunks; ++k) ke += kinetic[k], pw += power[k];
  s.external_work += c.dt * pw;
  const Real inf = std::numeric_limits<Real>::infinity();
  r.force_ratio = w.damping.external > 0 ? std::sqrt(w.damping.unbalanced / w.damping.external) : inf;
  r.energy_ratio = s.external_work > 0 ? ke / s.external_work : inf;
  if (c.ramp >= 1 && r.force_ratio < m.damping.force_ratio && r.energy_ratio < m.damping.energy_ratio) {
    s.damping_released = true;
    r.damping_released = true;
  }
}

void SensorsStage(const Model& m, const StepContext& c, State&, Workspace& w, StepReport& r) {
  SumSensors(m, c, w.grid, w.contact, r.sensors);
}

void ObstacleProjectionStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                             StepReport& r) {
  ProjectParticlesOutOfObstacles(m, c, s.rigid, w.grid, s.particles, w.contact, &r.obstacles);
  // The end checks passed before the projection (a stress stage ran them): the particles it moved
  // and slowed take them again.
  if (!w.end_checks_passed) return;
  EndChecks checks{DomainBox::Of(m)};
  for (const auto& list : w.contact.moved)
    for (const ProjectedParticle& moved : list)
      checks.Test(s.particles, moved.particle, Det3(s.particles.F[moved.particle]));
  w.end_checks_passed = checks.clean;
}

void GridToParticleUslStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                            StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, &w.velocity_gradient, nullptr);
}

namespace {
void FusedGridToParticleStress(const Model& m, const StepContext& c, State& s, Workspace& w,
                               bool end_checks) {
  // The internal work of UpdateStressStage, W += dt/2 (P_n + P_{n+1}), from each run's sum, added
  // in run order (the runs depend on the grid only, not on the thread count).
  const bool energy = m.output.energy;
  const size_t runs = w.grid.runs.size();
  w.run_power.assign(energy ? runs : 0, 0.0);
  w.run_clean.assign(end_checks ? runs : 0, 0);
  // The sink captures one reference, so that std::function keeps it without a heap allocation.
  const struct {
    const Model& m;
    const StepContext& c;
    State& s;
    Workspace& w;
    bool energy, end_checks;
    DomainBox box;
  } run_args{m, c, s, w, energy, end_checks, DomainBox::Of(m)};
  const GradientSink sink = [&a = run_args](size_t run, const uint32_t* ids, const Mat3* L,
                                            size_t n) {
    // The tests run on each particle right after its update, while it is in cache: its state is
    // final for this step (see GridToParticleStressCheckStage).
    EndChecks checks{a.box};
    const Real power = UpdateStressOfRun(a.m, a.c, ids, L, n, a.s.particles, a.energy,  // (2.18)-(2.20)
                                         a.end_checks ? &checks : nullptr);
    if (a.energy) a.w.run_power[run] = power;
    if (a.end_checks) a.w.run_clean[run] = checks.clean;
  };
  GridToParticle(m, c, w.grid, s.particles, nullptr, nullptr, &sink);
  if (energy) {
    Real total = 0;
    for (Real power : w.run_power) total += power;
    s.internal_work += 0.5 * c.dt * total;
  }
  // The runs cover every particle once (BinParticles).
  w.end_checks_passed =
      end_checks && std::all_of(w.run_clean.begin(), w.run_clean.end(), [](uint8_t v) { return v; });
}
}  // namespace

void GridToParticleStressStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                               StepReport&) {
  FusedGridToParticleStress(m, c, s, w, false);
}

void GridToParticleStressCheckStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                                    StepReport&) {
  FusedGridToParticleStress(m, c, s, w, true);
}

namespace {
// The positions the grid was binned with, x_n, for the stages after G2P that need them: the
// particles' own while their advection is deferred (AdvectStage), else Workspace::x_new.
const std::vector<Vec3>& StartPositions(const Model& m, const State& s, const Workspace& w) {
  return DeferredAdvection(m) ? s.particles.x : w.x_new;
}
}  // namespace

void GridToParticleMuslStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                             StepReport&) {
  if (DeferredAdvection(m))
    GridToParticle(m, c, w.grid, s.particles, nullptr, nullptr, nullptr, /*advect=*/false);
  else
    GridToParticle(m, c, w.grid, s.particles, nullptr, &w.x_new);
}

void RemapMomentumStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                        StepReport&) {
  RemapMomentum(m, c, s.particles, w.grid);
  // The re-mapped velocities obey the obstacles too (no reaction logged: the step's impulse
  // was counted in ObstacleContact).
  if (!m.obstacles.empty())
    ApplyObstacleContact(m, c, s.rigid, w.grid, w.contact, nullptr, &s.particles);
}

void VelocityGradientStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                           StepReport&) {
  ComputeVelocityGradient(m, c, w.grid, s.particles, w.velocity_gradient);
  // Commit x_{n+1}: the re-mapped gradient needed x_n (deferred: AdvectStage moves them later).
  if (!DeferredAdvection(m)) s.particles.x.swap(w.x_new);
}

void GridToParticleUslKeepStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                                StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, &w.velocity_gradient, &w.x_new);
  s.particles.x.swap(w.x_new);  // commit x_{n+1}; x_new now holds x_n
}

void GridToParticleUslDeferStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                                 StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, &w.velocity_gradient, nullptr, nullptr,
                 /*advect=*/false);
}

void AdvectStage(const Model&, const StepContext& c, State& s, Workspace&, StepReport&) {
  AdvectParticles(c, s.particles);
}

void AntiLockingStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                      StepReport&) {
  ProjectVolumetricStrain(m, c, s.groups, s.particles, StartPositions(m, s, w), w.grid,
                          w.antilocking, w.velocity_gradient);
}

// Runs right after UpdateStress, with x_n, the positions the grid was binned with: the particles'
// own while the advection is deferred, else x_new (the USL keep stage and MUSL's velocity gradient
// stage swapped it there).
void StressAveragingStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                          StepReport&) {
  ProjectStress(m, c, s.groups, s.particles, StartPositions(m, s, w), w.grid, w.antilocking);
}

void UpdateStressStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                       StepReport&) {
  // Internal work for the energy balance (docs/stability.md, "Energy"): the trapezoid rule on
  // the stress power over the step, W += dt/2 (P_n + P_{n+1}), P = sum V sigma : d with the
  // rate of deformation d = sym(L) that the stress update uses (Mast 2013 (2.18)); UpdateStress
  // sums P_n + P_{n+1} in its own loop.
  Real power = 0;
  UpdateStress(m, c, w.velocity_gradient, s.groups, s.particles, m.output.energy ? &power : nullptr);
  if (m.output.energy) s.internal_work += 0.5 * c.dt * power;
}

void UpdateStressAdvectCheckStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                                  StepReport&) {
  Real power = 0;  // as UpdateStressStage
  EndChecks checks{DomainBox::Of(m)};
  checks.advect = true;
  checks.dt = c.dt;
  bool clean = false;
  UpdateStress(m, c, w.velocity_gradient, s.groups, s.particles, m.output.energy ? &power : nullptr,
               &checks, &clean);
  if (m.output.energy) s.internal_work += 0.5 * c.dt * power;
  w.end_checks_passed = clean;
}

void BulkViscosityRateStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                            StepReport&) {
  ComputeBulkViscosity(m, c, s.groups, s.particles, w.velocity_gradient, w.bulk_viscosity);
}

void BulkViscosityApplyStage(const Model&, const StepContext&, State& s, Workspace& w,
                             StepReport&) {
  ApplyBulkViscosity(s.particles, w.bulk_viscosity);
}

void BulkViscosityRestoreStage(const Model&, const StepContext&, State& s, Workspace& w,
                               StepReport&) {
  RestoreStress(s.particles, w.bulk_viscosity);
}

// Before G2P: the particles are at x_n, where the grid was binned (particle_shifting.h).
void ParticleShiftComputeStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                               StepReport&) {
  ComputeParticleShift(m, c, s.groups, s.particles, s.rigid, w.grid, w.shifting);
}

// After G2P (and MUSL's velocity gradient, and AdvectStage): particles.x holds x_{n+1}; obstacle
// projection, which follows, puts a particle shifted into an obstacle back on its surface.
void ParticleShiftApplyStage(const Model& m, const StepContext&, State& s, Workspace& w,
                             StepReport&) {
  ApplyParticleShift(m, s.particles, w.shifting);
}

namespace {
// Walled faces of the domain, in face order.
std::vector<int> WalledFaces(const Model& m) {
  std::vector<int> faces;
  for (int f = 0; f < 2 * m.dim; ++f)
    if (m.walls[f].kind != WallKind::kOpen) faces.push_back(f);
  return faces;
}
}  // namespace

std::vector<ForceChannel> ForceChannels(const Model& m) {
  std::vector<ForceChannel> channels;
  const std::vector<int> walled = WalledFaces(m);
  if (!walled.empty()) {
    ForceChannel domain{"domain", {}};
    for (int f : walled) domain.faces.push_back(FaceName(Face(f)));
    channels.push_back(std::move(domain));
  }
  for (const Obstacle& o : m.obstacles) channels.push_back({o.name, o.faces});
  for (const Sensor& s : m.sensors) channels.push_back({s.name, {}});
  for (const BodyContact& c : m.body_contacts) channels.push_back({c.name, {}});
  return channels;
}

void CollectForces(const Model& m, const StepReport& step, ContactReport& out) {
  const std::vector<int> walled = WalledFaces(m);
  out.structures.resize((walled.empty() ? 0 : 1) + m.obstacles.size() + m.sensors.size() +
                        m.body_contacts.size());
  size_t k = 0;
  if (!walled.empty()) {
    ObstacleForce& d = out.structures[k++];
    d = ObstacleForce{};
    const Real cell_area = m.dim == 3 ? m.dx * m.dx : m.dx;  // h^(d-1), Mast 2013 (7.15)
    for (int f : walled) {
      FaceForce face;
      face.force = step.walls.force[f];
      face.contact_nodes = step.walls.contact_nodes[f];
      face.contact_area = Real(face.contact_nodes) * cell_area;
      d.force += face.force;
      d.torque += step.walls.torque[f];
      d.contact_nodes += face.contact_nodes;
      d.faces.push_back(face);
    }
    d.contact_area = Real(d.contact_nodes) * cell_area;
    d.max_nodal_force = step.walls.max_nodal_force;
    if (d.contact_nodes > 0) {  // above the domain's lowest corner
      const Vec3 up = UpDirection(m);
      Real base = std::numeric_limits<Real>::infinity();
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) ? m.domain_max.x() : m.domain_min.x(),
                          (c & 2) ? m.domain_max.y() : m.domain_min.y(),
                          m.dim == 3 ? ((c & 4) ? m.domain_max.z() : m.domain_min.z()) : 0.0);
        base = std::min(base, up.dot(corner));
      }
      d.wetted_height = step.walls.max_elevation - base;
    }
  }
  for (size_t o = 0; o < m.obstacles.size(); ++o) {
    out.structures[k++] = o < step.obstacles.size() ? step.obstacles[o] : ObstacleForce{};
  }
  for (size_t s = 0; s < m.sensors.size(); ++s) {
    out.structures[k++] = s < step.sensors.size() ? step.sensors[s] : ObstacleForce{};
  }
  for (size_t c = 0; c < m.body_contacts.size(); ++c) {
    out.structures[k++] = c < step.body_contact.pairs.size() ? step.body_contact.pairs[c] : ObstacleForce{};
  }
}

// Particles beyond an open side leave the run (removed and counted, or the run stops, as
// Model::exit_policy says). A particle that crossed a walled side (possible only by round-off
// of the position update) is put back on the wall plane.
void DomainExitStage(const Model& m, const StepContext&, State& s, Workspace& w,
                     StepReport& r) {
  Particles& P = s.particles;
  const size_t n = P.size();
  r.removed_last_step = 0;
  // Every particle inside the box, as G2P found it (GridToParticleStressCheckStage): nothing to do.
  if (w.end_checks_passed) return;
  w.exit_flag.resize(n);
  const DomainBox box = DomainBox::Of(m);
  const int dim = box.dim;
  std::array<uint8_t, kReductionChunks> any{};
  ParallelChunks(n, [&](size_t chunk, size_t b, size_t e) {
    uint8_t any_here = 0;
    for (size_t p = b; p < e; ++p) {
      uint8_t exits = 0;
      for (int d = 0; d < dim; ++d) {
        Real& xd = P.x[p][d];
        if (xd < box.lo[d]) {
          if (box.open_lo[d]) exits = 1;
          else xd = box.lo[d];
        } else if (xd > box.hi[d]) {
          if (box.open_hi[d]) exits = 1;
          else xd = box.hi[d];
        }
      }
      w.exit_flag[p] = exits;
      any_here |= exits;
    }
    any[chunk] = any_here;
  });
  if (std::find(any.begin(), any.end(), 1) == any.end()) return;
  if (m.exit_policy == ExitPolicy::kStop) {
    const size_t p = size_t(std::find(w.exit_flag.begin(), w.exit_flag.end(), 1) - w.exit_flag.begin());
    const size_t count = size_t(std::count(w.exit_flag.begin(), w.exit_flag.end(), 1));
    const std::string body =
        size_t(P.body[p]) < m.bodies.size() ? m.bodies[size_t(P.body[p])].name : "?";
    r.health = Health{HealthStatus::kLeftDomain, P.id[p],
                      "particle id " + std::to_string(P.id[p]) + " (material '" +
                          m.materials[size_t(P.material[p])].name + "', body '" + body +
                          "') left the domain through an open side: position x = (" +
                          std::to_string(P.x[p].x()) + ", " + std::to_string(P.x[p].y()) + ", " +
                          std::to_string(P.x[p].z()) + ") at |v| = " + std::to_string(P.v[p].norm()) +
                          " m/s, found by stage domain_exit; " + std::to_string(count) +
                          " particles outside. Likely cause: the flow reaches an open side and "
                          "domain.on_exit is 'stop': enlarge the domain, close that side with a "
                          "wall, or set domain.on_exit: remove",
                      "domain_exit", "x"};
    return;
  }
  // Stable compaction; material groups shrink accordingly.
  size_t out = 0;
  for (MaterialGroup& g : s.groups) {
    const size_t begin = out;
    for (size_t p = g.begin; p < g.end; ++p) {
      if (w.exit_flag[p]) continue;
      if (out != p) P.Move(out, p);
      ++out;
    }
    g.begin = begin;
    g.end = out;
  }
  r.removed_last_step = int64_t(n - out);
  s.particles_removed += r.removed_last_step;
  P.Resize(out);
}

namespace {
// The particle fields the health check reads, in the order a step writes them: v and x in
// grid_to_particle, F in grid_to_particle (USL) or velocity_gradient (MUSL), stress in
// update_stress. Every field was finite and J > 0 at the end of the previous step (the check runs
// every step), so the earliest bad field in this order names the stage that produced it.
enum BadField : int { kFieldOk = 0, kFieldV, kFieldX, kFieldF, kFieldJ, kFieldStress, kFieldCount };
// Not a particle field: the energy guard of EnergyStage.
constexpr int kFieldEnergy = kFieldCount;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string Point(const Vec3& x, int dim) {
  std::string s = "(" + Num(x.x()) + ", " + Num(x.y());
  if (dim == 3) s += ", " + Num(x.z());
  return s + ")";
}

// The diagnostic of a failed health check (failure path only): the field and stage, the particle
// with its material and body, and the likely cause from the time step against the CFL limit
// dt <= C h / (c + |v|) (spec §1.7) of the stiffest material present.
// `what`: the energy guard's own description (field kFieldEnergy).
void DescribeUnhealthy(const Model& m, const StepContext& ctx, const State& s, size_t p, int field,
                       size_t count, Health& h, const std::string& what = "") {
  const Particles& P = s.particles;
  const Material& mat = m.materials[size_t(P.material[p])];
  const std::string body =
      size_t(P.body[p]) < m.bodies.size() ? m.bodies[size_t(P.body[p])].name : "?";
  const size_t setting = size_t(P.body[p]) < m.bodies.size()
                            ? size_t(m.bodies[size_t(P.body[p])].antilocking)
                            : size_t(P.material[p]);
  const bool antilocked = setting < m.antilocking.size() &&
                          m.antilocking[setting].method != AntiLockingMethod::kNone;
  // Stiffest material with particles: its wave speed bounds the stable step from above.
  Real c_max = 0;
  std::string stiffest;
  for (const MaterialGroup& g : s.groups) {
    if (g.end == g.begin) continue;
    const Real c = WaveSpeed(m.materials[size_t(g.material)]);
    if (c > c_max) c_max = c, stiffest = m.materials[size_t(g.material)].name;
  }
  const Real dt_wave = c_max > 0 ? ctx.dx / c_max : 0;  // CFL limit at rest (C = 1) [s]
  const Real courant = c_max > 0 ? ctx.dt * c_max / ctx.dx : 0;
  const Real speed = P.v[p].allFinite() ? P.v[p].norm() : std::numeric_limits<Real>::infinity();
  const Real J = P.F[p].allFinite() ? Det3(P.F[p]) : std::numeric_limits<Real>::quiet_NaN();
  const bool musl = m.scheme == UpdateScheme::kMusl;

  switch (field) {
    case kFieldV:
      h.field = "v";
      h.stage = "grid_to_particle";
      h.detail = "non-finite velocity v";
      break;
    case kFieldX:
      h.field = "x";
      h.stage = m.obstacles.empty() ? "grid_to_particle" : "grid_to_particle or obstacle_projection";
      h.detail = "non-finite position x (velocity finite, |v| = " + Num(speed) + " m/s)";
      break;
    case kFieldF:
      h.field = "F";
      h.stage = musl ? "velocity_gradient" : "grid_to_particle";
      if (antilocked) h.stage += " or anti_locking";
      h.detail = "non-finite deformation gradient F (v and x finite, |v| = " + Num(speed) + " m/s)";
      break;
    case kFieldJ:
      h.field = "J";
      h.stage = musl ? "velocity_gradient" : "grid_to_particle";
      if (antilocked) h.stage += " or anti_locking";
      h.detail = "inverted particle, det F = J = " + Num(J) + " <= 0 (|v| = " + Num(speed) + " m/s)";
      break;
    case kFieldEnergy:
      h.field = "E";
      h.stage = "energy";
      h.detail = what + "; the fastest particle is";
      break;
    default:
      h.field = "stress";
      h.stage = "update_stress";
      h.detail = "non-finite stress from a finite F (J = " + Num(J) + ", |v| = " + Num(speed) +
                 " m/s): the constitutive update failed";
      break;
  }
  h.detail += (field == kFieldEnergy ? " particle id " : " at particle id ") +
              std::to_string(P.id[p]) + " (material '" + mat.name + "', body '" + body +
              "', x = " + (P.x[p].allFinite() ? Point(P.x[p], m.dim) : std::string("non-finite")) +
              (field == kFieldEnergy ? ", |v| = " + Num(speed) + " m/s), found by stage energy. "
                                     : "), produced by stage " + h.stage + "; " +
                                           std::to_string(count) + " of " +
                                           std::to_string(P.size()) + " particles unhealthy. ");

  // Likely cause.
  const std::string cfl_text = "dt = " + Num(ctx.dt) + " s against the CFL limit h/c = " +
                               Num(dt_wave) + " s of material '" + stiffest +
                               "' (c = " + Num(c_max) + " m/s, h = " + Num(ctx.dx) +
                               " m): Courant number " + Num(courant);
  std::string cause;
  if (m.time.fixed_dt > 0 && courant > 1) {
    cause = "time.fixed_dt is above the CFL limit: " + cfl_text +
            " > 1. Remove time.fixed_dt (the automatic dt obeys the limit) or set it below " +
            Num(m.time.cfl * dt_wave) + " s.";
  } else if (courant > 1) {
    cause = "dt above the CFL limit: " + cfl_text + " > 1 (time.max_dt or a viscous bound did not " +
            "cap it). Lower time.cfl.";
  } else if (field == kFieldStress) {
    cause = "material '" + mat.name + "' could not be updated at this deformation (J = " + Num(J) +
            "); " + cfl_text + " (within the limit). Check its parameters; for impacts add " +
            "bulk_viscosity to it, or lower time.cfl.";
  } else if (field == kFieldJ) {
    cause = "the particle was compressed through zero volume in one step (velocity gradient x dt "
            ">= 1) although " + cfl_text + " is within the limit: an impact or a collapse faster "
            "than the grid resolves, or a node with tiny mass (an isolated particle at a cell "
            "edge). Add bulk_viscosity to material '" + mat.name + "' for shocks, or lower "
            "time.cfl (e.g. to 0.2).";
  } else if (field == kFieldEnergy) {
    cause = "an instability below the wave-speed limit (" + cfl_text + " is within it): the "
            "stable Courant number of this setup is lower than time.cfl (nearly incompressible "
            "material, isolated particles, stiff contact; docs/stability.md). Lower time.cfl "
            "(e.g. to 0.2).";
  } else {
    cause = "an instability that the CFL rule does not cover (" + cfl_text +
            " is within the limit): a node with tiny mass (isolated particles), a contact or "
            "an unstable material setting. Lower time.cfl (e.g. to 0.2); for shocks add "
            "bulk_viscosity.";
  }
  h.detail += "Likely cause: " + cause;
}
}  // namespace

// Health check (DESIGN §4 item 7): NaN/Inf in v, x, F or stress, and J = det F <= 0. The healthy
// path is one pass over the particles; the diagnostic (DescribeUnhealthy) runs only on failure.
void CheckStateStage(const Model& m, const StepContext& ctx, State& s, Workspace& w, StepReport& r) {
  // Every particle passed the fast test below in G2P (GridToParticleStressCheckStage).
  if (w.end_checks_passed) {
    w.end_checks_passed = false;
    return;
  }
  const Particles& P = s.particles;
  constexpr size_t kNone = std::numeric_limits<size_t>::max();
  std::array<std::array<size_t, kFieldCount>, kReductionChunks> first;
  for (auto& f : first) f.fill(kNone);
  std::array<size_t, kReductionChunks> bad{};
  ParallelChunks(P.size(), [&](size_t chunk, size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      if (SurelyHealthy(P, p, Det3(P.F[p]))) continue;
      int field = kFieldOk;
      if (!P.v[p].allFinite()) field = kFieldV;
      else if (!P.x[p].allFinite()) field = kFieldX;
      else if (!P.F[p].allFinite()) field = kFieldF;
      else if (!(Det3(P.F[p]) > 0)) field = kFieldJ;
      else if (!P.stress[p].allFinite()) field = kFieldStress;
      if (field == kFieldOk) continue;
      ++bad[chunk];
      if (first[chunk][size_t(field)] == kNone) first[chunk][size_t(field)] = p;
    }
  });
  size_t count = 0;
  for (size_t c : bad) count += c;
  if (count == 0) return;
  // The offender: the earliest field in step order, then the lowest index (thread-independent).
  for (int field = kFieldV; field < kFieldCount; ++field) {
    for (size_t c = 0; c < kReductionChunks; ++c) {
      const size_t p = first[c][size_t(field)];
      if (p == kNone) continue;
      Health h;
      h.status = field == kFieldJ ? HealthStatus::kInvertedElement : HealthStatus::kNonFinite;
      h.particle_id = P.id[p];
      DescribeUnhealthy(m, ctx, s, p, field, count, h);
      r.health = std::move(h);
      return;
    }
  }
}

EnergyRecord ComputeEnergy(const Model& m, const State& s) {
  const Particles& P = s.particles;
  std::array<Real, kReductionChunks> kin{}, pot{};
  ParallelChunks(P.size(), [&](size_t c, size_t b, size_t e) {
    Real k = 0, g = 0;
    for (size_t p = b; p < e; ++p) {
      k += 0.5 * P.mass[p] * P.v[p].squaredNorm();
      g -= P.mass[p] * m.gravity.dot(P.x[p]);  // potential -m g.x, zero at the origin
    }
    kin[c] = k;
    pot[c] = g;
  });
  EnergyRecord e;
  for (size_t c = 0; c < kReductionChunks; ++c) {
    e.kinetic += kin[c];
    e.gravitational += pot[c];
  }
  e.strain = StrainEnergy(m, s.groups, P);
  e.wall_work = s.wall_work;
  e.internal_work = s.internal_work;
  e.time = s.time;
  e.step = s.step;
  e.dt = s.dt;
  return e;
}

// Energy record, and the energy guard (docs/stability.md): where nothing can do work on the
// particles (fixed walls and obstacles, no tractions, no gravity ramp), the mechanical energy
// E = kinetic + strain + gravitational, measured from the domain's lowest corner so that it is
// never negative, cannot grow; a step that leaves it above kEnergyGuardFactor x its value at the
// first step is a numerical blow-up that has not (yet) produced a NaN or an inverted particle,
// and stops the run. Cost: a comparison per step (the energy is computed anyway), plus a pass over
// the masses on steps where particles left.
void EnergyStage(const Model& m, const StepContext& ctx, State& s, Workspace& w, StepReport& r) {
  r.energy = ComputeEnergy(m, s);
  if (r.health.status != HealthStatus::kOk) return;
  constexpr Real kEnergyGuardFactor = 2;
  Workspace::EnergyGuard& g = w.energy_guard;
  const Particles& P = s.particles;
  auto mass = [&] {
    Real sum = 0;
    for (Real mp : P.mass) sum += mp;
    return sum;
  };
  if (!g.set) {
    g.set = true;
    const bool moving = std::any_of(m.obstacles.begin(), m.obstacles.end(), [](const Obstacle& o) {
      return o.motion.kind != ObstacleMotionKind::kFixed;
    });
    const bool tractions = std::any_of(P.ext_force.begin(), P.ext_force.end(),
                                       [](const Vec3& f) { return !f.isZero(0); });
    g.floor = std::numeric_limits<Real>::infinity();
    for (int c = 0; c < 8; ++c) {
      const Vec3 corner((c & 1) ? m.domain_max.x() : m.domain_min.x(),
                        (c & 2) ? m.domain_max.y() : m.domain_min.y(),
                        m.dim == 3 ? ((c & 4) ? m.domain_max.z() : m.domain_min.z()) : 0.0);
      g.floor = std::min(g.floor, -m.gravity.dot(corner));  // potential per kg, -g.x
    }
    g.floor_energy = g.floor * mass();
    g.reference = r.energy.kinetic + r.energy.strain + r.energy.gravitational - g.floor_energy;
    g.active = !moving && !tractions && m.gravity_ramp <= 0 && g.reference > 0;
    return;
  }
  if (!g.active) return;
  if (r.removed_last_step > 0) g.floor_energy = g.floor * mass();
  const Real e = r.energy.kinetic + r.energy.strain + r.energy.gravitational - g.floor_energy;
  if (!(e > kEnergyGuardFactor * g.reference)) return;
  size_t fastest = 0;
  for (size_t p = 1; p < P.size(); ++p)
    if (P.v[p].squaredNorm() > P.v[fastest].squaredNorm()) fastest = p;
  Health h;
  h.status = HealthStatus::kEnergyGrowth;
  h.particle_id = P.size() > 0 ? P.id[fastest] : -1;
  const std::string what =
      "mechanical energy (kinetic + strain + gravity above the domain floor) grew from " +
      Num(g.reference) + " J to " + Num(e) + " J (x" + Num(e / g.reference) +
      ") although nothing does work on the particles (fixed walls and obstacles, no tractions, "
      "no gravity ramp): a numerical blow-up";
  if (P.size() > 0) {
    DescribeUnhealthy(m, ctx, s, fastest, kFieldEnergy, 0, h, what);
  } else {
    h.field = "E";
    h.stage = "energy";
    h.detail = what;
  }
  r.health = std::move(h);
}

}  // namespace surge

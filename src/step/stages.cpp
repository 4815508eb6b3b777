// Stage adapters and the small stages owned by the step library: domain exit, health check
// and energy balance (STYLE H.7; DESIGN §4 items 7-8).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

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
}

void GridUpdateStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                     StepReport& r) {
  UpdateGridVelocity(m, c, w.grid, r.walls);
  s.wall_work += r.walls.work;
}

void ObstacleContactStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                          StepReport& r) {
  ApplyObstacleContact(m, c, s.rigid, w.grid, w.contact, &r.obstacles);
}

void BodyContactStage(const Model& m, const StepContext& c, State&, Workspace& w,
                      StepReport& r) {
  ApplyBodyContact(m, c, w.grid, r.walls, r.body_contact);
}

void LocalDampingStage(const Model&, const StepContext& c, State&, Workspace& w, StepReport&) {
  if (c.damping > 0) ApplyLocalDamping(c, w.grid);
}

void SensorsStage(const Model& m, const StepContext& c, State&, Workspace& w, StepReport& r) {
  SumSensors(m, c, w.grid, w.contact, r.sensors);
}

void ObstacleProjectionStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                             StepReport& r) {
  ProjectParticlesOutOfObstacles(m, c, s.rigid, w.grid, s.particles, w.contact, &r.obstacles);
}

void GridToParticleUslStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                            StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, &w.velocity_gradient, nullptr);
}

void GridToParticleMuslStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                             StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, nullptr, &w.x_new);
}

void RemapMomentumStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                        StepReport&) {
  RemapMomentum(m, c, s.particles, w.grid);
  // The re-mapped velocities obey the obstacles too (no reaction logged: the step's impulse
  // was counted in ObstacleContact).
  if (!m.obstacles.empty()) ApplyObstacleContact(m, c, s.rigid, w.grid, w.contact, nullptr);
}

void VelocityGradientStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                           StepReport&) {
  ComputeVelocityGradient(m, c, w.grid, s.particles, w.velocity_gradient);
  s.particles.x.swap(w.x_new);  // commit x_{n+1}: the re-mapped gradient needed x_n
}

void GridToParticleUslKeepStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                                StepReport&) {
  GridToParticle(m, c, w.grid, s.particles, &w.velocity_gradient, &w.x_new);
  s.particles.x.swap(w.x_new);  // commit x_{n+1}; x_new now holds x_n
}

void AntiLockingStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                      StepReport&) {
  ProjectVolumetricStrain(m, c, s.groups, s.particles, w.x_new, w.grid, w.antilocking,
                          w.velocity_gradient);
}

void UpdateStressStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                       StepReport&) {
  UpdateStress(m, c, w.velocity_gradient, s.groups, s.particles);
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
  w.exit_flag.assign(n, 0);
  std::array<uint8_t, kReductionChunks> any{};
  ParallelChunks(n, [&](size_t chunk, size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      for (int d = 0; d < m.dim; ++d) {
        const Real lo = m.domain_min[d], hi = m.domain_max[d];
        Real& xd = P.x[p][d];
        if (xd < lo) {
          if (m.walls[2 * d].kind == WallKind::kOpen) w.exit_flag[p] = 1;
          else xd = lo;
        } else if (xd > hi) {
          if (m.walls[2 * d + 1].kind == WallKind::kOpen) w.exit_flag[p] = 1;
          else xd = hi;
        }
      }
      any[chunk] |= w.exit_flag[p];
    }
  });
  r.removed_last_step = 0;
  if (std::find(any.begin(), any.end(), 1) == any.end()) return;
  if (m.exit_policy == ExitPolicy::kStop) {
    const size_t p = size_t(std::find(w.exit_flag.begin(), w.exit_flag.end(), 1) - w.exit_flag.begin());
    r.health = Health{HealthStatus::kLeftDomain, P.id[p],
                      "particle left the domain through an open side at x = (" +
                          std::to_string(P.x[p].x()) + ", " + std::to_string(P.x[p].y()) + ", " +
                          std::to_string(P.x[p].z()) + ") and domain.on_exit is 'stop'"};
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

// NaN/Inf in x, v or stress, and J <= 0; records the first offender in particle order.
void CheckStateStage(const Model&, const StepContext&, State& s, Workspace&, StepReport& r) {
  const Particles& P = s.particles;
  std::array<size_t, kReductionChunks> first;
  first.fill(std::numeric_limits<size_t>::max());
  std::array<int, kReductionChunks> kind{};
  ParallelChunks(P.size(), [&](size_t chunk, size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      const bool finite = P.x[p].allFinite() && P.v[p].allFinite() && P.stress[p].allFinite();
      const Real J = P.F[p].determinant();
      if (!finite || !(J > 0)) {
        first[chunk] = p;
        kind[chunk] = finite ? 2 : 1;
        return;
      }
    }
  });
  for (size_t c = 0; c < kReductionChunks; ++c) {
    if (first[c] == std::numeric_limits<size_t>::max()) continue;
    const size_t p = first[c];
    if (kind[c] == 1) {
      r.health = Health{HealthStatus::kNonFinite, P.id[p],
                        "non-finite position, velocity or stress (time step too large for the "
                        "material, or an unstable setup)"};
    } else {
      r.health = Health{HealthStatus::kInvertedElement, P.id[p],
                        "det F = " + std::to_string(P.F[p].determinant()) + " <= 0 (inverted particle)"};
    }
    return;
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
  e.time = s.time;
  e.step = s.step;
  e.dt = s.dt;
  return e;
}

void EnergyStage(const Model& m, const StepContext&, State& s, Workspace&, StepReport& r) {
  r.energy = ComputeEnergy(m, s);
}

}  // namespace surge

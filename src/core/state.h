// State: exactly what a checkpoint holds (STYLE H.4): a restart from it is bitwise identical.
#pragma once
#include <cstdint>
#include <vector>

#include "contact/obstacle.h"
#include "core/particles.h"

namespace surge {

// A contiguous particle range [begin, end) of one material (particles are grouped by material,
// so UpdateStress does one std::visit per group and then a monomorphic loop) and one anti-locking
// setting (each group is projected over its own particles only): bodies of one material share a
// group unless a body overrides the material's anti-locking.
struct MaterialGroup {
  int material = 0;
  size_t begin = 0;
  size_t end = 0;
  int antilocking = -1;  // index into Model::antilocking; -1: the material's own (index material)

  int AntiLockingIndex() const { return antilocking < 0 ? material : antilocking; }
};

struct State {
  Real time = 0;       // simulated time [s]
  int64_t step = 0;    // completed steps
  Real dt = 0;         // time step used by the last completed step [s]
  Particles particles;
  std::vector<MaterialGroup> groups;
  int64_t particles_removed = 0;  // particles that left through open domain sides
  Real wall_work = 0;             // cumulative work done on the particles by walls [J]
  // Local damping's equilibrium rule (LocalDamping::Equilibrium): damping has been switched off,
  // and the work of gravity on the particles while the rule watched (W_ext of (6.30)) [J].
  bool damping_released = false;
  Real external_work = 0;
  Real internal_work = 0;         // cumulative stress work sum_p V sigma : d dt on the particles
                                  // (trapezoid per step; stored + dissipated) [J]
  std::vector<RigidBodyState> rigid;  // dynamic obstacles (ObstacleMotion::body), Bullet-stepped
};

}  // namespace surge

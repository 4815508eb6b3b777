// What one step reports besides the State: energies and health (STYLE H.7).
#pragma once
#include <cstdint>
#include <string>

#include "core/math.h"

namespace surge {

// Energy balance terms [J] at the end of a step. 2-D values are per metre of thickness.
struct EnergyRecord {
  Real time = 0;
  int64_t step = 0;
  Real dt = 0;
  Real kinetic = 0;        // sum 1/2 m |v|^2
  Real strain = 0;         // sum psi(F) V0 (hyperelastic) or 1/2 sigma:eps V (linear elastic)
  Real gravitational = 0;  // sum -m g . x  (zero level at the origin)
  Real wall_work = 0;      // cumulative work of the domain walls on the particles
  Real internal_work = 0;  // cumulative stress work on the particles, sum V sigma : d dt: the strain
                           // energy stored plus the work dissipated by plasticity and viscosity
};

enum class HealthStatus {
  kOk,
  kNonFinite,
  kInvertedElement,
  kLeftDomain,
  kTimeStepTooSmall,
  kEnergyGrowth  // energy guard: mechanical energy doubled without external work (EnergyStage)
};

struct Health {
  HealthStatus status = HealthStatus::kOk;
  int64_t particle_id = -1;  // first offender (seeding id)
  std::string detail;        // field and value, the particle, the likely cause: the diagnostic
  std::string stage;         // the stage that produced the bad value (StageName), or "time_step"
  std::string field;         // "v", "x", "F", "J", "stress", "dt", "E"
};

}  // namespace surge

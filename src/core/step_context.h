// Quantities derived once at the start of a step and read by every stage (STYLE H.3).
#pragma once
#include "core/math.h"

namespace surge {

struct StepContext {
  Real time = 0;              // t_n [s]
  Real dt = 0;                // Delta t [s] (CFL, spec §1.7)
  Real dx = 0;                // cell size [m]
  Real inv_dx = 0;            // 1/dx [1/m]
  Real ramp = 1;              // external load factor min(t/t_c, 1) (seed App. B.2.3)
  Vec3 gravity = Vec3::Zero();  // ramped gravity [m/s^2]
  Real damping = 0;           // local damping factor alpha of this step (Model::damping) [-]
  Real mass_scale = 1;        // inertia factor beta of this step (Model::mass_scaling) [-]
};

}  // namespace surge

// Display names of the core enums.
#include "core/model.h"
#include "core/stage.h"

namespace surge {

const char* StageName(Stage s) {
  static constexpr const char* kNames[kStageCount] = {
      "rebuild_grid",     "reorder_particles", "particle_to_grid",    "grid_update",
      "obstacle_contact", "body_contact",      "local_damping",     "grid_to_particle",  "remap_momentum",      "velocity_gradient",
      "obstacle_projection", "rigid_bodies",   "sensors",        "anti_locking",   "update_stress",       "bulk_viscosity",      "particle_shifting", "domain_exit",
      "check_state",      "energy"};
  return kNames[static_cast<int>(s)];
}

const char* FaceName(Face f) {
  static constexpr const char* kNames[kFaceCount] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  return kNames[static_cast<int>(f)];
}

}  // namespace surge

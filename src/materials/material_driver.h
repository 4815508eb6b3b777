// A one-particle material driver (no grid, spec §2.10): prescribed velocity gradients go
// through the engine's own UpdateStress, so the verification tests exercise the exact code a
// simulation runs.
#pragma once
#include <vector>

#include "core/model.h"
#include "core/state.h"

namespace surge {

struct MaterialPoint {
  Model model;                          // holds the one material
  std::vector<MaterialGroup> groups;    // one group: particle 0
  Particles particles;                  // one particle, unit reference volume
  std::vector<Mat3> velocity_gradient;  // L of the next step [1/s], one entry
};

// A point of `material` at F = I with the Cauchy stress `initial_stress` [Pa] and its history
// set as the scene builder sets a geostatic start (InitialHistory).
MaterialPoint MakeMaterialPoint(const Material& material,
                                const Mat3& initial_stress = Mat3::Zero());

// One step of length dt [s] with velocity gradient L [1/s]: F <- (I + dt L) F (2.18) and the
// material's stress update. Writes every particle field UpdateStress writes.
void StepMaterialPoint(MaterialPoint& point, const Mat3& L, Real dt);

}  // namespace surge

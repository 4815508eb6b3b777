// A one-particle material driver (no grid, spec §2.10): prescribed velocity gradients go
// through the engine's own UpdateStress, so the verification tests exercise the exact code a
// simulation runs.
#pragma once
#include <array>
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

// Mixed stress/strain control (Alawaji et al. 1992; Mast 2013 §3.8, spec §2.10). Symmetric
// components in Voigt order (xx, yy, zz, xy, yz, xz) flagged in `stress_controlled` are unknown
// rates d_ij, iterated until the Cauchy stress equals `target` there; every other component of
// L is prescribed. The iteration starts from the elastic stiffness C^e (3.46, erratum 1), as
// the seed does, and improves it by Broyden updates.
struct MixedControl {
  Mat3 L = Mat3::Zero();                    // prescribed velocity gradient [1/s]
  std::array<bool, 6> stress_controlled{};  // unknown components
  Mat3 target = Mat3::Zero();               // target Cauchy stress there [Pa]
};

// One mixed-control step of length dt [s]. Converges to |sigma_u - target_u| <= tol [Pa] in
// every controlled component; returns the iterations used, or -1 without convergence (the point
// is then left at the best iterate).
int MixedControlStep(MaterialPoint& point, const MixedControl& control, Real dt, Real tol);

// Voigt index pairs (i, j) of the six symmetric components, xx yy zz xy yz xz.
inline constexpr int kVoigtI[6] = {0, 1, 2, 0, 1, 0};
inline constexpr int kVoigtJ[6] = {0, 1, 2, 1, 2, 2};

}  // namespace surge

// Frictional fluid: the regularised Bingham fluid of materials/bingham_fluid.h with a
// pressure-dependent yield stress, Anura3D manual §7.2.3, eq. (7.38) (spec seed-anura3d.md
// §A.16.3), plus an optional cohesion c.
//
// Yield stress tau_y = c cos(phi) + p sin(phi), p = max(0, -tr(sigma)/3) (tension positive).
// (7.38) is the case c = 0. The cohesion term is the Mohr-Coulomb criterion (7.25)-(7.26) in its
// maximum-shear form, 1/2 (sigma_1 - sigma_3) = c cos(phi) + 1/2 (sigma_1 + sigma_3) sin(phi)
// (compression positive): the deviatoric stress 2 mu_eff dev(d) of a plane flow has
// sigma_zz = -p, so 1/2 (sigma_1 + sigma_3) = p and the flowing fluid meets Mohr-Coulomb
// exactly in plane shear. With phi = 0 it is a Bingham fluid of tau_y = c (clay-rich debris).
// Because the normal stresses of the fluid are isotropic (dev d has no normal part in a flow
// parallel to a slope), a layer on a slope of angle theta stops at tan(theta) = sin(phi), not at
// theta = phi: 26.6 deg for phi = 30 deg (docs/materials.md).
#pragma once
#include <algorithm>
#include <cmath>

#include "materials/bingham_fluid.h"

namespace surge {

// Yield stress tau_y [Pa] at the Cauchy mean stress sigma_m [Pa] (tension positive):
// c cos(phi) + p sin(phi) with p = max(0, -sigma_m) (7.38; spec §A.16.3 [REC]: tau_y = c cos(phi)
// in tension).
inline Real FrictionalYieldStress(const FrictionalFluidParams& p, Real sigma_m) {
  const Real pressure = std::max(Real(0), -sigma_m);
  return p.cohesion * std::cos(p.friction_angle) + pressure * std::sin(p.friction_angle);
}

// One stress update of a frictional fluid particle: J = det F_{n+1}, L the velocity gradient of
// the step [1/s], dt [s]. The pressure comes first from the equation of state (6.1); the
// deviatoric part is traceless, so p = -tr(sigma)/3 of the new stress is the EOS pressure.
// Writes the Cauchy stress and the yielded strain (history slot 0).
inline void FrictionalFluidUpdate(const FrictionalFluidParams& p, Real J, const Mat3& L,
                                  Real dt, History& history, Mat3& stress) {
  const Real sigma_m = FluidMeanStress(EquationOfStateOf(p), J);  // (6.1) or Tait
  stress = ViscoplasticFluidStress(sigma_m, FrictionalYieldStress(p, sigma_m), p.viscosity,
                                   p.max_viscosity, L, dt, history);  // (7.37)-(7.38)
}

}  // namespace surge

// Regularised (bi-viscous) Bingham fluid for mud and debris flows: Anura3D manual §7.2.2,
// eq. (7.37) with the erratum of spec seed-anura3d.md §A.16.3 / §A.18 #15; pressure from the
// equation of state of the Newtonian fluid (materials/newtonian_fluid.h, Mast 2013 (6.1)).
//
// Design: the manual describes Bingham as "linear elastic while tau < tau_y". We implement the
// standard bi-viscous regularisation instead (Beverly & Tanner 1992, J. Non-Newtonian Fluid
// Mech. 42:85-115; Frigaard & Nouar 2005, J. Non-Newtonian Fluid Mech. 127:1-26), which is the
// form (7.37) itself encodes: below the yield rate the material is a Newtonian fluid of
// viscosity mu_max. It needs no elastic state, so the stress is a function of J and d only
// (objective by construction) and one particle loop serves all fluids. The price: the
// "unyielded" zone creeps at the rate tau / mu_max, and the explicit viscous time-step limit
// scales with 1/mu_max (step/step.cpp, ViscousTimeStep). docs/materials.md quantifies both.
#pragma once
#include <cmath>

#include "core/particles.h"
#include "materials/material_params.h"
#include "materials/newtonian_fluid.h"

namespace surge {

// History slot of a Bingham or frictional fluid particle:
//   [kFluidYieldedStrain]  accumulated equivalent strain of yielded flow,
//                          sum dt sqrt(2/3 d':d') over the steps with mu_eff < mu_max [-]
// (the von Mises measure of j2.h; it shows where the material has flowed, not creep).
inline constexpr int kFluidYieldedStrain = kPlasticStrainSlot;
inline constexpr int kFluidHistorySlots = 1;  // slots used (Bingham and frictional fluids)

// The equation of state of a viscoplastic fluid, as a Newtonian fluid without viscosity, so the
// pressure and stored energy reuse FluidMeanStress and NewtonianFluidEnergy.
template <class P>
inline NewtonianFluidParams EquationOfStateOf(const P& p) {
  return NewtonianFluidParams{p.bulk_modulus, 0, p.equation_of_state, p.tait_gamma};
}

// Equivalent shear rate ||D|| = sqrt(2 d':d') [1/s] (spec §A.16.3 [REC]): gamma_dot in simple
// shear, where d12 = gamma_dot / 2.
inline Real ShearRateNorm(const Mat3& d) { return std::sqrt(2.0 * Dev(d).squaredNorm()); }

// Effective viscosity mu_eff = min(mu_d + tau_y / ||D||, mu_max) [Pa s] (7.37, corrected: the
// manual prints (mu_d + tau_y) / ||D||, erratum §A.18 #15). Written without the division so
// ||D|| = 0 gives mu_max. Pre: 0 <= viscosity < max_viscosity, yield_stress >= 0.
inline Real BinghamViscosity(Real viscosity, Real yield_stress, Real max_viscosity, Real rate) {
  if (viscosity * rate + yield_stress < max_viscosity * rate) {
    return viscosity + yield_stress / rate;
  }
  return max_viscosity;
}

// Stress of a viscoplastic fluid with mean stress sigma_m [Pa] and yield stress tau_y [Pa]:
// sigma = sigma_m 1 + 2 mu_eff dev(d), d = sym(L) (7.36)-(7.37). Adds the yielded equivalent
// strain of the step to history[kFluidYieldedStrain]. In steady simple shear the shear stress is
// tau_y + mu_d gamma_dot above gamma_dot_c = tau_y / (mu_max - mu_d), mu_max gamma_dot below.
inline Mat3 ViscoplasticFluidStress(Real sigma_m, Real yield_stress, Real viscosity,
                                    Real max_viscosity, const Mat3& L, Real dt, History& history) {
  const Mat3 dev_d = Dev(Sym(L));
  const Real rate = std::sqrt(2.0 * dev_d.squaredNorm());  // ||D|| (spec §A.16.3 [REC])
  const Real mu_eff = BinghamViscosity(viscosity, yield_stress, max_viscosity, rate);  // (7.37)
  if (mu_eff < max_viscosity) history[kFluidYieldedStrain] += dt * rate / std::sqrt(3.0);
  return sigma_m * Mat3::Identity() + 2.0 * mu_eff * dev_d;  // (7.36) with mu_d -> mu_eff
}

// One stress update of a Bingham particle: J = det F_{n+1}, L the velocity gradient of the step
// [1/s], dt [s]. Writes the Cauchy stress and the yielded strain (history slot 0).
inline void BinghamFluidUpdate(const BinghamFluidParams& p, Real J, const Mat3& L, Real dt,
                               History& history, Mat3& stress) {
  stress = ViscoplasticFluidStress(FluidMeanStress(EquationOfStateOf(p), J), p.yield_stress,
                                   p.viscosity, p.max_viscosity, L, dt, history);
}

}  // namespace surge

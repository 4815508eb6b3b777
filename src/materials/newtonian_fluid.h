// Weakly compressible Newtonian fluid: Mast (2013) §6.1, eqs. (6.1)-(6.2) (spec §2.3), with a
// linear (logarithmic) or Tait equation of state for the pressure.
#pragma once
#include <cmath>

#include "materials/material_params.h"

namespace surge {

// Mean Cauchy stress sigma_m = tr(sigma)/3 [Pa] (tension positive) at volume ratio J = rho0/rho.
//  linear: sigma_m = rho kbar theta = (K/J) ln J, kbar = K/rho0, theta = ln J (6.1), spec §2.3.
//  tait:   sigma_m = -p, p = B [(rho/rho0)^gamma - 1] with B = K/gamma, i.e. rho0 c0^2/gamma
//          (Tait equation with gamma = 7 for water: Cole 1948, Underwater Explosions (Princeton);
//          in this form in Monaghan 1994, J. Comput. Phys. 110:399-406, §3).
inline Real FluidMeanStress(const NewtonianFluidParams& p, Real J) {
  if (p.equation_of_state == EquationOfState::kTait) {
    const Real B = p.bulk_modulus / p.tait_gamma;
    return -B * (std::pow(J, -p.tait_gamma) - 1.0);
  }
  return p.bulk_modulus * std::log(J) / J;
}

// Cauchy stress sigma = sigma_m(J) 1 + 2 mu d, d = sym(L) of the current step (6.1)-(6.2).
// The seed writes the full d (not dev d): a bulk viscosity 2 mu / 3 comes with it.
inline Mat3 NewtonianFluidStress(const NewtonianFluidParams& p, Real J, const Mat3& L) {
  return FluidMeanStress(p, J) * Mat3::Identity() + 2.0 * p.viscosity * Sym(L);
}

// Stored volumetric energy per reference volume psi(J) = int_1^J sigma_m(J') dJ' [J/m^3]:
//  linear: K/2 (ln J)^2;  tait: B [(J^(1-gamma) - 1)/(gamma - 1) + J - 1].
inline Real NewtonianFluidEnergy(const NewtonianFluidParams& p, Real J) {
  if (p.equation_of_state == EquationOfState::kTait) {
    const Real g = p.tait_gamma;
    const Real B = p.bulk_modulus / g;
    return B * ((std::pow(J, 1.0 - g) - 1.0) / (g - 1.0) + J - 1.0);
  }
  const Real lnJ = std::log(J);
  return 0.5 * p.bulk_modulus * lnJ * lnJ;
}

}  // namespace surge

// Compressible Neo-Hookean hyperelasticity (Bonet & Wood 2008, eqs. (6.27)-(6.28)).
#pragma once
#include <cmath>

#include "materials/material_params.h"

namespace surge {

// Cauchy stress sigma = [G (b - I) + lambda ln(J) I] / J, b = F F^T.
inline Mat3 NeoHookeanStress(const NeoHookeanParams& p, const Mat3& F) {
  const Real J = Det3(F);
  const Real lambda = LameLambda(p.bulk_modulus, p.shear_modulus);
  return (p.shear_modulus * (F * F.transpose() - Mat3::Identity()) +
          lambda * std::log(J) * Mat3::Identity()) /
         J;
}

// psi = G/2 (tr(F^T F) - 3) - G ln J + lambda/2 (ln J)^2.
inline Real NeoHookeanEnergy(const NeoHookeanParams& p, const Mat3& F) {
  const Real lnJ = std::log(Det3(F));
  const Real lambda = LameLambda(p.bulk_modulus, p.shear_modulus);
  return 0.5 * p.shear_modulus * ((F.transpose() * F).trace() - 3.0) - p.shear_modulus * lnJ +
         0.5 * lambda * lnJ * lnJ;
}

}  // namespace surge

// Small-strain, hypo-elastic linear elasticity (Mast 2013 §3.2, eq. (3.10); spec §2.2).
#pragma once
#include "materials/material_params.h"

namespace surge {

// sigma_{n+1} = sigma_n + lambda tr(d_eps) I + 2 G d_eps, d_eps = sym(f - I) = dt sym(L).
// The rate is not objective: use neo_hookean for large rotations.
inline void LinearElasticUpdate(const LinearElasticParams& p, const Mat3& d_eps, Mat3& stress,
                                Mat3& strain) {
  const Real lambda = LameLambda(p.bulk_modulus, p.shear_modulus);
  stress += lambda * d_eps.trace() * Mat3::Identity() + 2.0 * p.shear_modulus * d_eps;
  strain += d_eps;
}

// psi = 1/2 sigma : eps (exact for zero initial stress).
inline Real LinearElasticEnergy(const Mat3& stress, const Mat3& strain) {
  return 0.5 * (stress.array() * strain.array()).sum();
}

}  // namespace surge

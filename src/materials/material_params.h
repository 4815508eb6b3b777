// Material parameter structs, one per constitutive model, held in a std::variant (STYLE H.4).
// Users give K and G (or E and nu); derived Lame constants are computed once by the builder.
// Plasticity models of later issues add a struct here and a case in update_stress.cpp.
#pragma once
#include <string>
#include <variant>

#include "core/math.h"

namespace surge {

// Small-strain linear elasticity, hypo-elastic incremental form (Mast 2013 §3.2, eq. (3.10)):
// sigma_{n+1} = sigma_n + lambda tr(d_eps) I + 2 G d_eps.
struct LinearElasticParams {
  Real bulk_modulus = 0;   // K [Pa]
  Real shear_modulus = 0;  // G [Pa]
};

// Compressible Neo-Hookean hyperelasticity (Bonet & Wood 2008, eq. (6.28)):
// tau = G (F F^T - I) + lambda ln(J) I;  psi = G/2 (tr C - 3) - G ln J + lambda/2 (ln J)^2.
struct NeoHookeanParams {
  Real bulk_modulus = 0;   // K [Pa]
  Real shear_modulus = 0;  // G [Pa]
};

using MaterialParams = std::variant<LinearElasticParams, NeoHookeanParams>;

struct Material {
  std::string name;
  Real density = 0;  // reference density rho_0 [kg/m^3]
  MaterialParams params;
};

// Lame's first parameter from K and G: lambda = K - 2G/3.
inline Real LameLambda(Real bulk, Real shear) { return bulk - 2.0 * shear / 3.0; }

// Dilatational (P-)wave speed c = sqrt((K + 4G/3)/rho_0), used by the CFL rule (spec §1.7).
inline Real WaveSpeed(const Material& m) {
  return std::visit(
      [&](const auto& p) {
        return std::sqrt((p.bulk_modulus + 4.0 * p.shear_modulus / 3.0) / m.density);
      },
      m.params);
}

}  // namespace surge

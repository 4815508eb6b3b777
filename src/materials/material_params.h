// Material parameter structs, one per constitutive model, held in a std::variant (STYLE H.4).
// Users give K and G (or E and nu); derived Lame constants are computed once by the builder.
// Plasticity models of later issues add a struct here and a case in update_stress.cpp.
#pragma once
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>

#include "core/math.h"
#include "materials/friction_angles.h"

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

// J2 (von Mises) plasticity at finite strain with linear isotropic and linear (Prager) kinematic
// hardening (Mast 2013 §3.5, eqs. (3.69)-(3.83); spec §2.4). Hencky elasticity in Kirchhoff
// stress, tau = K tr(eps_e) 1 + 2G dev(eps_e); history layout in materials/j2.h.
struct J2Params {
  Real bulk_modulus = 0;         // K [Pa]
  Real shear_modulus = 0;        // G [Pa]
  Real yield_stress = 0;         // sigma_Y, uniaxial [Pa]
  Real isotropic_hardening = 0;  // k, slope of uniaxial stress vs plastic strain [Pa]
  Real kinematic_hardening = 0;  // H, Prager modulus, back stress = 2/3 H alpha_kin [Pa]
};

// Mohr-Coulomb, elastic-perfectly plastic, non-associated (Anura3D manual §7.1.2.2, (7.25)-(7.27);
// spec seed-anura3d.md §A.16.2): planes (tau_i - tau_j) + (tau_i + tau_j) sin(phi) = 2 c cos(phi),
// potential with psi; principal return in materials/mohr_coulomb.h (history layout there).
struct MohrCoulombParams {
  Real bulk_modulus = 0;    // K [Pa]
  Real shear_modulus = 0;   // G [Pa]
  Real friction_angle = 0;  // phi [rad], 0 <= phi < pi/2
  Real dilation_angle = 0;  // psi [rad], 0 <= psi <= phi
  Real cohesion = 0;        // c, Kirchhoff strength [Pa]; apex at tau_m = c cot(phi)
  // Rankine tension cut-off t: tau_i <= t (Kirchhoff) [Pa]; infinity: none (the apex bounds
  // tension). Associated flow on the cut-off planes (materials/mohr_coulomb.h).
  Real tension_cutoff = std::numeric_limits<Real>::infinity();
};

// Tresca, elastic-perfectly plastic (Anura3D manual §7.1.2.1, (7.24)): max shear |tau_i - tau_j|/2
// <= s_u; Mohr-Coulomb with phi = psi = 0 and c = s_u (materials/mohr_coulomb.h).
struct TrescaParams {
  Real bulk_modulus = 0;        // K [Pa]
  Real shear_modulus = 0;       // G [Pa]
  Real undrained_strength = 0;  // s_u, shear strength (Kirchhoff) [Pa]
  Real tension_cutoff = std::numeric_limits<Real>::infinity();  // t as for Mohr-Coulomb [Pa]
};

// Dense snow: modified Cam-clay with cohesion (Gaume et al. 2018, Nat. Commun. 9:3047, Methods):
// y = (1 + 2 beta) q^2 + M^2 (p + beta p0)(p - p0) <= 0, p compression positive, hardening
// p0 = K sinh(xi max(-eps_v^p, 0)); Hencky elasticity; history layout in materials/snow.h.
struct SnowParams {
  Real bulk_modulus = 0;            // K [Pa]; also the scale of the hardening law
  Real shear_modulus = 0;           // G [Pa]
  Real critical_state_slope = 0;    // M, slope of the Cam-clay ellipse (beta = 0: q/p at CS) [-]
  Real cohesion_ratio = 0;          // beta, tensile / compressive strength of the cap [-]
  Real hardening_factor = 0;        // xi, compaction hardening factor of the sinh law [-]
  Real consolidation_pressure = 0;  // p0 at the start (compressive strength of the cap) [Pa]
};

// Pressure law of the Newtonian fluid.
enum class EquationOfState {
  kLinear,  // sigma_m = K ln(J) / J (Mast 2013 eq. (6.1) with theta = ln J)
  kTait     // p = B [(rho/rho0)^gamma - 1], B = K / gamma (Monaghan 1994)
};

// Weakly compressible Newtonian fluid (Mast 2013 §6.1, eqs. (6.1)-(6.2); spec §2.3):
// sigma = sigma_m(J) 1 + 2 mu d.
struct NewtonianFluidParams {
  Real bulk_modulus = 0;  // K = rho0 c0^2 [Pa]
  Real viscosity = 0;     // dynamic viscosity mu [Pa s]
  EquationOfState equation_of_state = EquationOfState::kLinear;
  Real tait_gamma = 7;    // Tait exponent gamma [-] (kTait only)
};

// Regularised Bingham fluid (Anura3D manual §7.2.2, eq. (7.37) corrected, spec §A.16.3):
// sigma = sigma_m(J) 1 + 2 mu_eff dev(d), mu_eff = min(mu_d + tau_y / ||D||, mu_max),
// ||D|| = sqrt(2 d':d'); sigma_m(J) from the Newtonian fluid's EOS. materials/bingham_fluid.h.
struct BinghamFluidParams {
  Real bulk_modulus = 0;   // K = rho0 c0^2 [Pa]
  Real viscosity = 0;      // mu_d, plastic (Bingham) viscosity above yield [Pa s]
  Real yield_stress = 0;   // tau_y, shear yield stress [Pa]
  Real max_viscosity = 0;  // mu_max, cap of mu_eff below the yield rate [Pa s]
  EquationOfState equation_of_state = EquationOfState::kLinear;
  Real tait_gamma = 7;     // Tait exponent gamma [-] (kTait only)
};

// Frictional fluid (Anura3D manual §7.2.3, eq. (7.38), spec §A.16.3): the Bingham fluid with
// tau_y = c cos(phi) + p sin(phi), p = max(0, -tr(sigma)/3). materials/frictional_fluid.h.
struct FrictionalFluidParams {
  Real bulk_modulus = 0;    // K = rho0 c0^2 [Pa]
  Real viscosity = 0;       // mu_d, viscosity above yield [Pa s]
  Real friction_angle = 0;  // phi [rad]
  Real cohesion = 0;        // c [Pa]
  Real max_viscosity = 0;   // mu_max, cap of mu_eff below the yield rate [Pa s]
  EquationOfState equation_of_state = EquationOfState::kLinear;
  Real tait_gamma = 7;      // Tait exponent gamma [-] (kTait only)
};

// Plastic potential of the Matsuoka-Nakai models (Mast 2013 §3.8): the MN function (3.123) (pure
// MN, verification only) or the Drucker-Prager cone (3.108) ("MN with DP G", the seed's
// recommended granular model).
enum class MatsuokaNakaiPotential { kMatsuokaNakai, kDruckerPrager };

// Two-surface Matsuoka-Nakai with evolving friction and dilation angles (Mast 2013 §3.7, eqs.
// (3.120)-(3.128); spec §2.8): F = 6 kappa_F I3' - 6 I1' I2' of the shifted stress tau - c_F 1,
// angles (3.112)-(3.114); history layout in materials/matsuoka_nakai.h.
struct MatsuokaNakaiParams {
  Real bulk_modulus = 0;   // K [Pa]
  Real shear_modulus = 0;  // G [Pa]
  Real cohesion = 0;       // c_F, hydrostatic shift: apex at sigma = c_F 1 [Pa]
  FrictionCurve friction;  // a0..a5 of (3.113)-(3.114) (a2 in 1/Pa)
  bool zero_dilation = false;  // psi_G forced to 0 (seed Table 7.2 runs)
  MatsuokaNakaiPotential potential = MatsuokaNakaiPotential::kMatsuokaNakai;
};

// Modified two-surface Drucker-Prager with evolving friction and dilation angles (Mast 2013
// §3.6.3-3.6.4, eqs. (3.106)-(3.116); spec §2.7): the DP cone through the Mohr-Coulomb
// compression vertices of the mobilised angle, tension cutoff at the apex; history layout in
// materials/modified_drucker_prager.h.
struct ModifiedDruckerPragerParams {
  Real bulk_modulus = 0;       // K [Pa]
  Real shear_modulus = 0;      // G [Pa]
  Real cohesion = 0;           // c, Mohr-Coulomb cohesion (3.107) [Pa]
  FrictionCurve friction;      // a0..a5 of (3.113)-(3.114) (a2 in 1/Pa)
  bool zero_dilation = false;  // psi_G forced to 0 (seed Table 7.2 runs)
};

// Traditional two-surface Drucker-Prager with tension cutoff and linear isotropic/kinematic
// hardening (Mast 2013 §3.6.1; spec §2.5); history layout in materials/drucker_prager.h.
struct DruckerPragerParams {
  Real bulk_modulus = 0;         // K [Pa]
  Real shear_modulus = 0;        // G [Pa]
  Real friction_slope = 0;       // varrho_F of the friction angle (3.107) [-]
  Real dilation_slope = 0;       // varrho_G of the dilation angle (3.109) [-]
  Real yield_stress = 0;         // sigma_Y: F1 = ||eta|| + varrho_F I1 - sqrt(2/3) sigma_Y at alpha = 0 [Pa]
  Real isotropic_hardening = 0;  // k [Pa]
  Real kinematic_hardening = 0;  // H [Pa]
};

// Smooth-cap two-surface Drucker-Prager (Mast 2013 §3.6.2; spec §2.6): the seed's workhorse for
// impact studies; history layout in materials/smooth_cap_drucker_prager.h.
struct SmoothCapDruckerPragerParams {
  Real bulk_modulus = 0;    // K [Pa]
  Real shear_modulus = 0;   // G [Pa]
  Real friction_slope = 0;  // varrho_F of the friction angle (3.107) [-]
  Real yield_stress = 0;    // mu, effective yield stress (cohesion-like), > 0 [Pa]
  Real associativity = 0;   // varrho_G / varrho_F in [0, 1] [-]
};

using MaterialParams =
    std::variant<LinearElasticParams, NeoHookeanParams, J2Params, NewtonianFluidParams,
                 BinghamFluidParams, FrictionalFluidParams, SnowParams,
                 MatsuokaNakaiParams, MohrCoulombParams, TrescaParams,
                 ModifiedDruckerPragerParams, SmoothCapDruckerPragerParams,
                 DruckerPragerParams>;

// Fluids: stress from J and d only (no shear modulus, no elastic state).
template <class P>
inline constexpr bool kIsFluid = std::is_same_v<P, NewtonianFluidParams> ||
                                 std::is_same_v<P, BinghamFluidParams> ||
                                 std::is_same_v<P, FrictionalFluidParams>;

// Elastoplastic models: Hencky elasticity in Kirchhoff stress with b^e as the state (Table 3.4).
// Their stress update is PlasticUpdate(params, f, J, b^e, history, sigma), found by overload.
template <class P>
inline constexpr bool kIsElastoplastic =
    !std::is_same_v<P, LinearElasticParams> && !std::is_same_v<P, NeoHookeanParams> &&
    !kIsFluid<P>;

struct Material {
  std::string name;
  Real density = 0;  // reference density rho_0 [kg/m^3]
  MaterialParams params;
  // Particle shifting by the delta-correction (src/stabilize/particle_shifting.h; scene key
  // `particle_shifting`): this material's particles move apart where they crowd.
  bool particle_shifting = false;
};

// Lame's first parameter from K and G: lambda = K - 2G/3.
inline Real LameLambda(Real bulk, Real shear) { return bulk - 2.0 * shear / 3.0; }

// Dilatational (P-)wave speed c = sqrt((K + 4G/3)/rho_0), used by the CFL rule (spec §1.7).
// A fluid has no shear modulus: c = sqrt(K/rho_0), the speed at the reference density (the Tait
// law stiffens under compression, by (rho/rho0)^((gamma-1)/2): 3 % at 1 % compression).
inline Real WaveSpeed(const Material& m) {
  return std::visit(
      [&](const auto& p) {
        if constexpr (kIsFluid<std::decay_t<decltype(p)>>) {
          return std::sqrt(p.bulk_modulus / m.density);
        } else {
          return std::sqrt((p.bulk_modulus + 4.0 * p.shear_modulus / 3.0) / m.density);
        }
      },
      m.params);
}

}  // namespace surge

// Mohr-Coulomb (non-associated) and Tresca perfect plasticity at finite strain: the yield and
// potential planes of the Anura3D manual §7.1.2 (eqs. (7.24)-(7.27)), written tension positive,
// with the principal-space return to the main plane, the two edges and the apex (Clausen,
// Damkilde & Andersen 2006, IJNME 66:1036; de Souza Neto, Peric & Owen 2008 §8.2;
// spec seed-anura3d.md §A.16.2 [REC]) inside the Hencky/b^e skeleton of Mast (2013) Table 3.4
// (materials/hencky.h). docs/materials.md ("Mohr-Coulomb and Tresca") has the equations.
//
// Everything is in Kirchhoff stress tau = J sigma (Table 3.4): the cohesion c and s_u are
// Kirchhoff strengths; the Cauchy strength is c / J (J stays near 1 for soils).
#pragma once
#include <limits>

#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots (Particles::history) of a Mohr-Coulomb or Tresca particle:
//   [kMcPlasticStrain]      equivalent plastic strain sum sqrt(2/3 d_eps^p : d_eps^p) [-], with
//                           d_eps^p = eps_tr - eps_e the principal plastic Hencky increment of a
//                           step (volumetric part included; for Tresca it is deviatoric)
//   [kMcVolumetricPlastic]  eps_v^p = sum tr(d_eps^p) = ln J^p, tension (dilation) positive [-]
//   [kMcReturnRegion]       region of the last update, a McRegion value (diagnostic)
inline constexpr int kMcPlasticStrain = kPlasticStrainSlot;
inline constexpr int kMcVolumetricPlastic = 1;
inline constexpr int kMcReturnRegion = 2;
inline constexpr int kMcHistorySlots = 3;  // slots used

// Where a return lands (principal stresses sorted tau_1 >= tau_2 >= tau_3, tension positive).
enum class McRegion {
  kElastic = 0,
  kMainPlane = 1,  // f_13 = 0 only
  kLeftEdge = 2,   // tau_1 = tau_2: triaxial compression meridian, planes f_13 = f_23 = 0
  kRightEdge = 3,  // tau_2 = tau_3: triaxial extension meridian, planes f_13 = f_12 = 0
  kApex = 4,       // tau_i = c cot(phi), deviator zero (phi > 0 only)
  kTension = 5,    // on a tension cut-off plane tau_i = t (alone, at a corner or at tau = t 1)
};

// The six planes of a model as sines and cosines; Tresca is phi = psi = 0, c = s_u.
struct McSurface {
  Real sin_phi = 0;
  Real cos_phi = 1;
  Real sin_psi = 0;
  Real cohesion = 0;  // c [Pa]
  Real tension = std::numeric_limits<Real>::infinity();  // Rankine cut-off t: tau_i <= t [Pa]
};
McSurface SurfaceOf(const MohrCoulombParams& params);
McSurface SurfaceOf(const TrescaParams& params);

// Yield function f = max over i != j of (tau_i - tau_j) + (tau_i + tau_j) sin(phi) - 2 c cos(phi)
// [Pa]: the six planes of (7.26) (x 2, tension positive); for sorted values the (1, 3) plane.
// Any order of `tau` (permutation invariant). f <= 0 inside.
Real MohrCoulombYield(const McSurface& surface, const Vec3& tau);

// Principal return of the trial Kirchhoff stress `trial` sorted trial_1 >= trial_2 >= trial_3,
// with the elastic principal block of [C^e_d] (K, G). `tau` keeps the order (tau_1 >= tau_2 >=
// tau_3); dgamma holds the multipliers of the planes used (main, second) [-].
// With a tension cut-off (surface.tension finite), a state whose Mohr-Coulomb return leaves
// tau_1 > t is returned to the admissible set {f_ij <= 0, tau_i <= t} of all nine planes
// (Koiter's multi-surface rule, exact for these linear planes: region kTension).
struct McReturn {
  Vec3 tau = Vec3::Zero();
  McRegion region = McRegion::kElastic;
  Real dgamma[2] = {0, 0};
};
McReturn MohrCoulombReturn(const McSurface& surface, Real K, Real G, const Vec3& trial);

// One stress update. Reads f = I + dt L, J = det F_{n+1}, b^e_n and the history; writes b^e_{n+1},
// the history and sigma_{n+1}. Pre: det f > 0, b^e_n symmetric positive definite, K, G > 0,
// 0 <= psi <= phi < 90 deg, c >= 0 (s_u > 0 for Tresca).
void MohrCoulombUpdate(const McSurface& surface, Real K, Real G, const Mat3& f, Real J,
                       Mat3& elastic_b, History& history, Mat3& stress);
// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller.
void MohrCoulombUpdate(const McSurface& surface, Real K, Real G, const HenckyTrial& t, Real J,
                       Mat3& elastic_b, History& history, Mat3& stress);

inline void PlasticUpdate(const MohrCoulombParams& params, const Mat3& f, Real J,
                          Mat3& elastic_b, History& history, Mat3& stress) {
  MohrCoulombUpdate(SurfaceOf(params), params.bulk_modulus, params.shear_modulus, f, J, elastic_b,
                    history, stress);
}
inline void PlasticUpdate(const TrescaParams& params, const Mat3& f, Real J, Mat3& elastic_b,
                          History& history, Mat3& stress) {
  MohrCoulombUpdate(SurfaceOf(params), params.bulk_modulus, params.shear_modulus, f, J, elastic_b,
                    history, stress);
}
inline void PlasticUpdate(const MohrCoulombParams& params, const Mat3&, const HenckyTrial& t,
                          Real J, Mat3& elastic_b, History& history, Mat3& stress) {
  MohrCoulombUpdate(SurfaceOf(params), params.bulk_modulus, params.shear_modulus, t, J, elastic_b,
                    history, stress);
}
inline void PlasticUpdate(const TrescaParams& params, const Mat3&, const HenckyTrial& t, Real J,
                          Mat3& elastic_b, History& history, Mat3& stress) {
  MohrCoulombUpdate(SurfaceOf(params), params.bulk_modulus, params.shear_modulus, t, J, elastic_b,
                    history, stress);
}

}  // namespace surge

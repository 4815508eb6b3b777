// J2 (von Mises) plasticity at finite strain with linear isotropic and linear (Prager) kinematic
// hardening: Mast (2013) §3.5, eqs. (3.69)-(3.83), with the finite-deformation return of
// Table 3.4 (spec seed-algorithms.md §2.1, §2.4; errata 2 and 3 of spec §9 applied).
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots (Particles::history) of a J2 particle:
//   [kJ2PlasticStrain]           alpha_iso, equivalent plastic strain sum sqrt(2/3) dgamma [-]
//   [kJ2BackStress + 0 .. + 5]   back stress beta = -kappa_kin (Kirchhoff, deviatoric) [Pa],
//                                components xx yy zz xy yz xz
inline constexpr int kJ2PlasticStrain = kPlasticStrainSlot;
inline constexpr int kJ2BackStress = 1;
inline constexpr int kJ2HistorySlots = 7;  // slots used: plastic strain and 6 back stress

// One stress update. Reads the incremental deformation gradient f = I + dt L, J = det F_{n+1},
// b^e_n and the history; writes b^e_{n+1}, the history and the Cauchy stress sigma_{n+1}.
// Pre: det f > 0, b^e_n symmetric positive definite, parameters positive (k, H >= 0).
void J2Update(const J2Params& params, const Mat3& f, Real J, Mat3& elastic_b, History& history,
              Mat3& stress);

// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller.
void J2Update(const J2Params& params, const Mat3& f, const HenckyTrial& t, Real J, Mat3& elastic_b,
              History& history, Mat3& stress);

inline void PlasticUpdate(const J2Params& params, const Mat3& f, Real J, Mat3& elastic_b,
                          History& history, Mat3& stress) {
  J2Update(params, f, J, elastic_b, history, stress);
}
inline void PlasticUpdate(const J2Params& params, const Mat3& f, const HenckyTrial& t, Real J,
                          Mat3& elastic_b, History& history, Mat3& stress) {
  J2Update(params, f, t, J, elastic_b, history, stress);
}

// Yield function F = ||dev tau - beta|| - sqrt(2/3) (sigma_Y + k alpha_iso) [Pa] (3.69)-(3.72),
// evaluated at the Kirchhoff stress tau = J sigma. F <= 0 on or inside the yield surface.
Real J2YieldFunction(const J2Params& params, const Mat3& tau, const History& history);

// Back stress beta [Pa] stored in `history`, and its store (slots kJ2BackStress..+5).
Mat3 J2BackStressOf(const History& history);
void J2StoreBackStress(const Mat3& beta, History& history);

}  // namespace surge

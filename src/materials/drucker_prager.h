// Traditional two-surface Drucker-Prager with a tension cutoff and linear isotropic and
// kinematic hardening (Mast 2013 §3.6.1, eqs. (3.84)-(3.100); spec seed-algorithms.md §2.5,
// errata 4 and 5): cone F1 = ||eta|| + varrho_F I1 - sqrt(2/3)(sigma_Y + k alpha) with
// eta = s - beta, potential G1 with varrho_G, cutoff F2 = I1 - c at the initial apex. varrho_F = 0
// is J2 (materials/j2.h). Finite strain: Hencky elasticity in Kirchhoff stress, b^e state.
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots: the J2 layout (materials/j2.h) —
//   [0]      alpha, equivalent plastic strain sum sqrt(2/3) dgamma_1 [-]
//   [1 .. 6] back stress beta (Kirchhoff, deviatoric), xx yy zz xy yz xz [Pa]
//   [7]      plastic volumetric strain sum tr d eps^p, dilation positive [-]
inline constexpr int kDpPlasticVolume = 7;
inline constexpr int kDpHistorySlots = 8;  // slots used

void PlasticUpdate(const DruckerPragerParams& params, const Mat3& f, Real J, Mat3& elastic_b,
                   History& history, Mat3& stress);
// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller.
void PlasticUpdate(const DruckerPragerParams& params, const Mat3& f, const HenckyTrial& t, Real J,
                   Mat3& elastic_b, History& history, Mat3& stress);

// Cone yield function F1 at the Kirchhoff stress tau with the stored hardening [Pa] (3.84).
Real DruckerPragerYield(const DruckerPragerParams& params, const Mat3& tau,
                        const History& history);

// I1 of the tension cutoff: the apex of the initial cone, sqrt(2/3) sigma_Y / varrho_F >= 0
// (erratum 4); it does not move with hardening (kappa_2 = 0). +infinity for varrho_F = 0.
Real DruckerPragerApex(const DruckerPragerParams& params, const History& history);

}  // namespace surge

// Modified two-surface Drucker-Prager with evolving friction and dilation angles (Mast 2013
// §3.6.3-3.6.4, eqs. (3.106)-(3.116); spec seed-algorithms.md §2.7, errata 4, 5, 7, 9, 10).
// Cone F = ||s|| + varrho_F I1 + sigma_Y^Eff (3.106)-(3.107) through the Mohr-Coulomb compression
// vertices, potential G = ||s|| + varrho_G I1 - C_G (3.108), tension cutoff at the apex (§2.5).
// Semi-implicit (Tu, Andrade & Chen 2009): the angles are frozen over the step and updated from
// the converged state; the cone return is then closed form (spec §2.7 [REC]).
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots of a modified Drucker-Prager particle:
//   [kMdpLambda]       lambda, plastic deformation measure sum dgamma (3.116), deviatoric norm
//                      (spec [REC]); also the equivalent plastic strain of results (slot 0) [-]
//   [kMdpFriction]     phi_F, mobilised friction angle for the next step [deg]
//   [kMdpCritical]     phi_cs, critical-state friction angle [deg]
//   [kMdpDilation]     psi_G, dilation angle for the next step [deg]
inline constexpr int kMdpLambda = kPlasticStrainSlot;
inline constexpr int kMdpFriction = 1;
inline constexpr int kMdpCritical = 2;
inline constexpr int kMdpDilation = 3;
inline constexpr int kMdpHistorySlots = 4;  // slots used

void PlasticUpdate(const ModifiedDruckerPragerParams& params, const Mat3& f, Real J,
                   Mat3& elastic_b, History& history, Mat3& stress);
// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller.
void PlasticUpdate(const ModifiedDruckerPragerParams& params, const Mat3& f, const HenckyTrial& t,
                   Real J, Mat3& elastic_b, History& history, Mat3& stress);

// Angles at lambda = 0 for a start at Cauchy stress `stress` (F = I).
void InitialPlasticHistory(const ModifiedDruckerPragerParams& params, const Mat3& stress,
                           History& history);

// Yield function F(tau) with the angles stored in `history` [Pa] (3.106); F <= 0 admissible.
Real ModifiedDruckerPragerYield(const ModifiedDruckerPragerParams& params, const Mat3& tau,
                                const History& history);

}  // namespace surge

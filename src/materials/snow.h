// Dense snow: modified Cam-clay with cohesion and sinh compaction hardening (Gaume, Gast, Teran,
// van Herwijnen & Jiang 2018, Nat. Commun. 9:3047, Methods; Gaume et al. 2019, CRST 168:102847),
// with an associative, fully implicit return in principal Hencky space (Mast 2013 Table 3.4).
// docs/materials.md ("Dense snow") gives the equations, the departures and parameter sets.
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots (Particles::history) of a snow particle:
//   [kSnowPlasticStrain]        eps_q^p, deviatoric equivalent plastic strain sum (q_tr - q)/(3G) [-]
//   [kSnowVolumetricPlastic]    alpha = eps_v^p = ln J^p, volumetric plastic strain (tension
//                               positive) counted from a virgin state (p0 = 0); it starts at
//                               -asinh(p0_init/K)/xi, so compaction (alpha < 0) hardens [-]
//   [kSnowConsolidation]        p0 = K sinh(xi max(-alpha, 0)), current consolidation pressure [Pa]
inline constexpr int kSnowPlasticStrain = kPlasticStrainSlot;
inline constexpr int kSnowVolumetricPlastic = 1;
inline constexpr int kSnowConsolidation = 2;
inline constexpr int kSnowHistorySlots = 3;  // slots used

// Hardening law p0(alpha) = K sinh(xi max(-alpha, 0)) [Pa] (Gaume et al. 2018, Methods).
Real SnowConsolidationPressure(const SnowParams& params, Real alpha);

// Yield function y = (1 + 2 beta) q^2 + M^2 (p + beta p0)(p - p0) [Pa^2] (Gaume et al. 2018,
// Methods) with p = -tr(tau)/3 (compression positive) and q = sqrt(3/2) |dev tau|, at the
// Kirchhoff stress tau = J sigma and the p0 held in `history`. y <= 0 inside.
Real SnowYieldFunction(const SnowParams& params, const Mat3& tau, const History& history);

// Magnitude of the terms of y, (1 + 2 beta) q^2 + M^2 (|p| + beta p0)(|p| + p0) [Pa^2]: the scale
// against which a relative yield-surface error is measured.
Real SnowYieldScale(const SnowParams& params, const Mat3& tau, const History& history);

// Critical-state stress ratio q/p at the top of the ellipse, p_cs = (1 - beta) p0 / 2:
// M (1 + beta) / ((1 - beta) sqrt(1 + 2 beta)) (equals M for beta = 0). Pre: beta < 1.
Real SnowCriticalStateRatio(const SnowParams& params);

// One stress update. Reads f = I + dt L, J = det F_{n+1}, b^e_n and the history; writes b^e_{n+1},
// the history and sigma_{n+1}. Pre: det f > 0, b^e_n symmetric positive definite, K, G, M > 0,
// 0 <= beta <= 1, xi > 0.
void SnowUpdate(const SnowParams& params, const Mat3& f, Real J, Mat3& elastic_b, History& history,
                Mat3& stress);

// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller.
void SnowUpdate(const SnowParams& params, const HenckyTrial& t, Real J, Mat3& elastic_b,
                History& history, Mat3& stress);

inline void PlasticUpdate(const SnowParams& params, const Mat3& f, Real J, Mat3& elastic_b,
                          History& history, Mat3& stress) {
  SnowUpdate(params, f, J, elastic_b, history, stress);
}
inline void PlasticUpdate(const SnowParams& params, const Mat3&, const HenckyTrial& t, Real J,
                          Mat3& elastic_b, History& history, Mat3& stress) {
  SnowUpdate(params, t, J, elastic_b, history, stress);
}

// History of a particle starting at the Cauchy stress `stress` with F = I: p0 = p0_init, raised to
// the smallest p0 whose surface holds `stress` when p0_init does not (a normally consolidated
// geostatic start), and alpha = -asinh(p0/K)/xi consistent with it.
void InitialPlasticHistory(const SnowParams& params, const Mat3& stress, History& history);

}  // namespace surge

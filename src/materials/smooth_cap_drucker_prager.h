// Smooth-cap two-surface Drucker-Prager (Mast 2013 §3.6.2, eq. (3.101); spec seed-algorithms.md
// §2.6 with erratum 6): the Drucker-Prager cone F1 = ||s|| + varrho_F I1 - mu for I1 <= I_t and,
// beyond the tangent point, the sphere F2 = sqrt(||s||^2 + I1^2/3) - R_t about the stress origin
// (Swan & Seo 2006 without their compression cap), R_t = mu / sqrt(1 + 3 varrho_F^2),
// I_t = 3 varrho_F mu / (1 + 3 varrho_F^2). Non-associated on the cone (varrho_G =
// associativity x varrho_F), associated on the cap; no hardening. The seed's workhorse for its
// landslide, avalanche and column-impact studies (Tables 7.8, 7.10, 7.12).
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots of a smooth-cap Drucker-Prager particle:
//   [kScdpPlasticStrain]  equivalent plastic strain sum ||dev d eps^p|| [-]
//   [kScdpPlasticVolume]  plastic volumetric strain sum tr d eps^p (dilation positive) [-]
//   [kScdpRegion]         surface of the last return: 0 elastic, 1 cone, 2 cap, 3 tangent ring
inline constexpr int kScdpPlasticStrain = kPlasticStrainSlot;
inline constexpr int kScdpPlasticVolume = 1;
inline constexpr int kScdpRegion = 2;
inline constexpr int kScdpHistorySlots = 3;  // slots used

void PlasticUpdate(const SmoothCapDruckerPragerParams& params, const Mat3& f, Real J,
                   Mat3& elastic_b, History& history, Mat3& stress);
// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b) computed by the caller
// (UpdateStress decomposes two particles' trial b^e at once: SymmetricEigen2).
void PlasticUpdate(const SmoothCapDruckerPragerParams& params, const Mat3& f, const HenckyTrial& t,
                   Real J, Mat3& elastic_b, History& history, Mat3& stress);

// The same for four particles (t[k], J[k], elastic_b[k], history[k], stress[k]), each bitwise
// what the one above gives: the yield test, the cone, cap and ring returns and the plastic-strain
// increments run in four lanes (AVX where WideSimd(), core/simd.h); a particle with a non-finite
// trial stress returns through the scalar code.
void PlasticUpdate4(const SmoothCapDruckerPragerParams& params, const HenckyTrial* t, const Real* J,
                    Mat3* elastic_b, History* history, Mat3* stress);

// Principal-space return of a trial Kirchhoff stress (exposed for tests). Returns the region
// (0 elastic, 1 cone, 2 cap, 3 tangent ring) and writes the returned principal stresses.
int SmoothCapReturn(const SmoothCapDruckerPragerParams& params, const Vec3& tau_trial, Vec3& tau);

// Yield function of the surface that applies at I1 = tr(tau) [Pa]; <= 0 admissible.
Real SmoothCapYield(const SmoothCapDruckerPragerParams& params, const Vec3& tau);

}  // namespace surge

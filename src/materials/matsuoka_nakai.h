// Two-surface Matsuoka-Nakai soil model with evolving friction and dilation
// angles (Mast 2013 §3.7, eqs. (3.120)-(3.128), App. A.2.2; spec
// seed-algorithms.md §2.8) and its "MN with DP G" variant (MN yield surface,
// Drucker-Prager potential (3.108)), integrated by the semi-implicit return of
// Tu, Andrade & Chen (2009) in principal Kirchhoff space (Table 3.4,
// (3.48)-(3.51)).
#pragma once
#include "core/particles.h"
#include "materials/material_params.h"

namespace surge {

struct HenckyTrial;  // materials/hencky.h

// History slots (Particles::history) of a Matsuoka-Nakai particle:
//   [kMnPlasticStrain]       equivalent plastic strain sum sqrt(2/3) |dev d
//   eps^p| [-] [kMnLambda]              lambda, plastic deformation measure sum
//   |dev d eps^p| (3.115), the
//                            spec's [REC] deviatoric norm |dgamma I_dev : g|
//                            [-]
//   [kMnFrictionAngle]       phi_F, mobilised friction angle of the next return
//   (3.113) [deg] [kMnCriticalAngle]       phi_cs, critical-state friction
//   angle (3.114) [deg] [kMnDilationAngle]       psi_G, dilation angle of the
//   next return (3.112) [deg] [kMnVolumetricPlastic]   eps_v^p, accumulated
//   plastic volume change sum tr(d eps^p) [-]
//                            (tension positive: > 0 is dilation)
inline constexpr int kMnPlasticStrain = kPlasticStrainSlot;
inline constexpr int kMnLambda = 1;
inline constexpr int kMnFrictionAngle = 2;
inline constexpr int kMnCriticalAngle = 3;
inline constexpr int kMnDilationAngle = 4;
inline constexpr int kMnVolumetricPlastic = 5;
inline constexpr int kMnHistorySlots = 6;  // slots used

// kappa = (sin^2 phi - 9) / (sin^2 phi - 1) (3.121), (3.124); phi in degrees,
// |phi| < 90.
Real MatsuokaNakaiKappa(Real phi_deg);

// Principal-space Matsuoka-Nakai function of a stress with principal values
// `tau` [Pa]: F = 6 kappa I3' - 6 I1' I2' [Pa^3], the primes denoting
// invariants of the shifted stress tau - c 1 ((3.120) with ||s||^2 = 2/3 (I1^2
// - 3 I2); equal to the expanded (3.122)).
Real MatsuokaNakaiFunction(Real kappa, Real cohesion, const Vec3 &tau);
// Its gradient dF/dtau_I (3.125)/(A.21) [Pa^2] and Hessian d2F/dtau_I dtau_J
// (3.127)/(A.25) [Pa], written in the shifted principal values.
Vec3 MatsuokaNakaiGradient(Real kappa, Real cohesion, const Vec3 &tau);
Mat3 MatsuokaNakaiHessian(Real kappa, Real cohesion, const Vec3 &tau);
// Trace of the gradient in unshifted invariants, (3.128) with erratum 8 of spec
// §9: tr g = (6 kappa - 18) I2 - 12 I1^2 + 12 c (9 - kappa) I1 + c^2 (18 kappa
// - 162) [Pa^2].
Real MatsuokaNakaiGradientTrace(Real kappa, Real cohesion, const Vec3 &tau);

// Yield function F at the Kirchhoff stress tau = J sigma with the friction
// angle held in `history` [Pa^3], and the magnitude of its terms 6 (kappa |I3'|
// + |I1' I2'|) [Pa^3], the scale of the relative yield-surface error |F| /
// scale.
Real MatsuokaNakaiYieldFunction(const MatsuokaNakaiParams &params,
                                const Mat3 &tau, const History &history);
Real MatsuokaNakaiYieldScale(const MatsuokaNakaiParams &params, const Mat3 &tau,
                             const History &history);

// Outcome of one principal-space return.
struct MatsuokaNakaiReturn {
  Vec3 tau = Vec3::Zero(); // principal Kirchhoff stress after the return [Pa]
  Vec3 plastic_strain =
      Vec3::Zero();      // d eps^p = eps_tr - [D^e_d] tau, principal [-]
  int iterations = 0;    // Newton iterations (both attempts)
  bool apex = false;     // tension cutoff: tau = c 1
  bool fallback = false; // Newton restarted from the DP outer-cone return
  bool converged = true; // false: radial projection onto F = 0 was used
};

// Semi-implicit return (Tu et al. 2009) of the principal trial state (eps_tr,
// tau_tr) with the angles phi_F, psi_G [deg] frozen: the 4x4 Newton
// (3.48)-(3.51) on {tau, dgamma}. Pre: the trial state is plastic (F > 0 or a
// shifted principal stress >= 0).
MatsuokaNakaiReturn MatsuokaNakaiReturnMap(const MatsuokaNakaiParams &params,
                                           const Vec3 &eps_tr,
                                           const Vec3 &tau_tr, Real phi_f_deg,
                                           Real psi_g_deg);

// One stress update. Reads f = I + dt L, J = det F_{n+1}, b^e_n and the
// history; writes b^e_{n+1}, the history (angles updated after the return,
// semi-implicit) and sigma_{n+1}. Pre: det f > 0, b^e_n symmetric positive
// definite, history set by InitialPlasticHistory.
void MatsuokaNakaiUpdate(const MatsuokaNakaiParams &params, const Mat3 &f,
                         Real J, Mat3 &elastic_b, History &history,
                         Mat3 &stress);

// The same from the trial state t = HenckyTrialState(K, G, f, elastic_b)
// computed by the caller.
void MatsuokaNakaiUpdate(const MatsuokaNakaiParams &params,
                         const HenckyTrial &t, Real J, Mat3 &elastic_b,
                         History &history, Mat3 &stress);

inline void PlasticUpdate(const MatsuokaNakaiParams &params, const Mat3 &f,
                          Real J, Mat3 &elastic_b, History &history,
                          Mat3 &stress) {
  MatsuokaNakaiUpdate(params, f, J, elastic_b, history, stress);
}
inline void PlasticUpdate(const MatsuokaNakaiParams &params, const Mat3 &,
                          const HenckyTrial &t, Real J, Mat3 &elastic_b,
                          History &history, Mat3 &stress) {
  MatsuokaNakaiUpdate(params, t, J, elastic_b, history, stress);
}

// History of a particle starting at the Cauchy stress `stress` with F = I:
// lambda = 0 and the angles of (3.112)-(3.114) at I1 = tr(sigma); when the
// stress lies outside that initial surface (a geostatic K0 start), lambda is
// raised along the hardening branch of phi_F until the surface holds the stress
// (at most to the peak, lambda* = 1/a3 + a4/a1).
void InitialPlasticHistory(const MatsuokaNakaiParams &params,
                           const Mat3 &stress, History &history);

} // namespace surge

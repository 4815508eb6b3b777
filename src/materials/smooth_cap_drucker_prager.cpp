// Smooth-cap Drucker-Prager: closed-form cone return and a scalar-Newton closest-point return to
// the spherical cap, in principal Kirchhoff stress (Mast 2013 §3.6.2; spec §2.6).
#include "materials/smooth_cap_drucker_prager.h"

#include <algorithm>
#include <cmath>

#include "materials/hencky.h"

namespace surge {
namespace {

struct Cap {
  Real radius;      // R_t = mu / sqrt(1 + 3 varrho_F^2) [Pa]
  Real I1_tangent;  // I_t = 3 varrho_F mu / (1 + 3 varrho_F^2) [Pa]
  Real s_tangent;   // ||s||_t = mu / (1 + 3 varrho_F^2) [Pa]
};

Cap CapOf(const SmoothCapDruckerPragerParams& p) {
  const Real d = 1.0 + 3.0 * p.friction_slope * p.friction_slope;
  return {p.yield_stress / std::sqrt(d), 3.0 * p.friction_slope * p.yield_stress / d,
          p.yield_stress / d};  // spec §2.6 [REC] reconstruction (erratum 6)
}

// The yield function of the surface that applies at I1, from the invariants I1 = tr(tau) and
// s = ||dev tau|| and the cap's constants.
Real YieldOf(const SmoothCapDruckerPragerParams& p, const Cap& cap, Real I1, Real s) {
  if (I1 <= cap.I1_tangent) return s + p.friction_slope * I1 - p.yield_stress;  // F1 (3.101)
  return std::sqrt(s * s + I1 * I1 / 3.0) - cap.radius;                         // F2
}

}  // namespace

Real SmoothCapYield(const SmoothCapDruckerPragerParams& p, const Vec3& tau) {
  const Real I1 = tau.sum();
  const Vec3 s = (tau.array() - I1 / 3.0).matrix();
  return YieldOf(p, CapOf(p), I1, s.norm());
}

int SmoothCapReturn(const SmoothCapDruckerPragerParams& p, const Vec3& tau_trial, Vec3& tau) {
  const Real K = p.bulk_modulus, G = p.shear_modulus;
  const Cap cap = CapOf(p);
  const Real I1 = tau_trial.sum();
  const Vec3 s = (tau_trial.array() - I1 / 3.0).matrix();
  const Real s_norm = s.norm();
  tau = tau_trial;
  if (YieldOf(p, cap, I1, s_norm) <= 0) return 0;  // the cap and invariants computed once

  const Real rho_f = p.friction_slope, rho_g = p.associativity * p.friction_slope;
  // Cone return (3.88)-(3.91) with H = k = 0, accepted if it lands on the cone part (I1 <= I_t)
  // without passing the hydrostatic axis: dgamma = F1 / (2G + 9K varrho_F varrho_G).
  const Real F1 = s_norm + rho_f * I1 - p.yield_stress;
  if (F1 > 0) {
    const Real dgamma = F1 / (2.0 * G + 9.0 * K * rho_f * rho_g);
    const Real I1_new = I1 - 9.0 * K * rho_g * dgamma;  // (3.89)
    if (s_norm - 2.0 * G * dgamma >= 0 && I1_new <= cap.I1_tangent) {
      tau = s * (1.0 - 2.0 * G * dgamma / s_norm) + Vec3::Constant(I1_new / 3.0);
      return 1;
    }
  }
  // Cap return: closest point on the sphere, associated, g = tau / |tau|. With x = dgamma / R_t,
  // s = s_tr / (1 + 2Gx) and I1 = I1_tr / (1 + 3Kx); x >= 0 solves
  // phi(x) = ||s_tr||^2 / (1 + 2Gx)^2 + I1_tr^2 / (3 (1 + 3Kx)^2) - R_t^2 = 0 (spec §2.6), where
  // phi decreases and is convex, so Newton from any x0 <= root converges monotonically. Each of
  // the two terms alone equal to R_t^2 gives such an x0 (the other term is >= 0 there, so
  // phi(x0) >= 0): x_s = (||s_tr|| / R_t - 1) / 2G and x_I = (|I1_tr| / (sqrt(3) R_t) - 1) / 3K.
  // Starting from the larger one, instead of x = 0, saves the ~log_1.5(||tau_tr|| / R_t) slow steps
  // Newton needs from 0 when the trial stress lies far outside the cap (a 10 Pa yield stress under
  // kPa stresses: 11-28 steps for trial stresses 10-10^4 R_t; now about 5, same root to 4e-16).
  Real x = std::max({0.0, (s_norm / cap.radius - 1.0) / (2.0 * G),
                     (std::abs(I1) / (std::sqrt(3.0) * cap.radius) - 1.0) / (3.0 * K)});
  for (int it = 0; it < 100; ++it) {
    const Real a = 1.0 + 2.0 * G * x, b = 1.0 + 3.0 * K * x;
    const Real phi = s_norm * s_norm / (a * a) + I1 * I1 / (3.0 * b * b) - cap.radius * cap.radius;
    const Real dphi = -4.0 * G * s_norm * s_norm / (a * a * a) - 2.0 * K * I1 * I1 / (b * b * b);
    if (dphi >= 0) break;
    const Real step = -phi / dphi;
    x += step;
    if (std::abs(step) <= 1e-15 * std::max(x, 1e-300)) break;
  }
  const Real I1_cap = I1 / (1.0 + 3.0 * K * x);
  if (I1_cap >= cap.I1_tangent) {
    const Real scale = cap.radius / std::sqrt(s_norm * s_norm / ((1 + 2 * G * x) * (1 + 2 * G * x)) +
                                              I1_cap * I1_cap / 3.0);  // round-off onto F2 = 0
    tau = (s / (1.0 + 2.0 * G * x) + Vec3::Constant(I1_cap / 3.0)) * scale;
    return 2;
  }
  // Between the cone's (non-associated) and the cap's return directions: the tangent ring
  // (I1 = I_t, ||s|| = ||s||_t) where the two surfaces meet, in the direction of s_tr.
  const Vec3 n = s_norm > 0 ? Vec3(s / s_norm) : Vec3::Zero();
  tau = cap.s_tangent * n + Vec3::Constant(cap.I1_tangent / 3.0);
  return 3;
}

void PlasticUpdate(const SmoothCapDruckerPragerParams& p, const Mat3& f, Real J, Mat3& elastic_b,
                   History& h, Mat3& stress) {
  const HenckyTrial t = HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b);
  PlasticUpdate(p, f, t, J, elastic_b, h, stress);
}

void PlasticUpdate(const SmoothCapDruckerPragerParams& p, const Mat3&, const HenckyTrial& t,
                   Real J, Mat3& elastic_b, History& h, Mat3& stress) {
  const Real K = p.bulk_modulus, G = p.shear_modulus;  // t: Table 3.4, steps 1-4
  Vec3 tau;
  const int region = SmoothCapReturn(p, t.tau, tau);
  h[kScdpRegion] = region;
  if (region != 0) {
    // Plastic strain increment in principal space: eps_tr - eps_e (Table 3.4 residual, row 1).
    const Vec3 dep = t.eps - HenckyStrain(K, G, tau);
    h[kScdpPlasticStrain] += (dep.array() - dep.sum() / 3.0).matrix().norm();
    h[kScdpPlasticVolume] += dep.sum();
  }
  HenckyFinish(t, K, G, tau, J, elastic_b, stress);  // Table 3.4, 5(c)-(d)
}

}  // namespace surge

// Smooth-cap Drucker-Prager: closed-form cone return and a scalar-Newton closest-point return to
// the spherical cap, in principal Kirchhoff stress (Mast 2013 §3.6.2; spec §2.6).
#include "materials/smooth_cap_drucker_prager.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/simd.h"
#include "materials/hencky.h"

#if SURGE_HAVE_WIDE_SIMD
#include <immintrin.h>  // _mm256_zeroupper (the wide return)
#endif

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

namespace {

// Four trial states for PlasticUpdate4, lane-major ([component][lane]), and what the lane return
// made of them: the returned principal stresses (in place), the region (0 elastic, 1 cone, 2 cap,
// 3 ring, -1 left to SmoothCapReturn) and the increments of the two plastic-strain sums.
struct ReturnGroup {
  alignas(32) Real tau[3][4];
  alignas(32) Real eps[3][4];
  alignas(32) Real region[4];
  alignas(32) Real d_strain[4];
  alignas(32) Real d_volume[4];
};

// The material constants of the lane return, each computed by the same expression as in
// SmoothCapReturn and PlasticUpdate, so each lane's result is bitwise theirs.
struct LaneConstants {
  Real K, G;
  Real rho_f, yield_stress;
  Real radius, I1_tangent, s_tangent;  // the cap's R_t, I_t and ||s||_t (CapOf)
  Real denominator;                    // 2G + 9K varrho_F varrho_G
  Real volume_factor;                  // 9K varrho_G
  Real radius_sqrt3;                   // sqrt(3) R_t
};

LaneConstants LaneConstantsOf(const SmoothCapDruckerPragerParams& p) {
  const Real K = p.bulk_modulus, G = p.shear_modulus;
  const Real rho_f = p.friction_slope, rho_g = p.associativity * p.friction_slope;
  const Cap cap = CapOf(p);
  return {K,
          G,
          rho_f,
          p.yield_stress,
          cap.radius,
          cap.I1_tangent,
          cap.s_tangent,
          2.0 * G + 9.0 * K * rho_f * rho_g,
          9.0 * K * rho_g,
          std::sqrt(3.0) * cap.radius};
}

using Mask4 = int64_t __attribute__((vector_size(4 * sizeof(int64_t))));

[[gnu::always_inline]] inline Real4 Load4(const Real* p) {
  Real4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void Store4(Real* p, Real4 v) { std::memcpy(p, &v, sizeof v); }
[[gnu::always_inline]] inline Real4 Splat4(Real a) { return Real4{a, a, a, a}; }
[[gnu::always_inline]] inline Real4 Sqrt4(Real4 a) {
  return Real4{__builtin_sqrt(a[0]), __builtin_sqrt(a[1]), __builtin_sqrt(a[2]),
               __builtin_sqrt(a[3])};
}

// SmoothCapReturn and PlasticUpdate's plastic-strain increments for four trial states in the
// lanes, each operation as the scalar code orders it: the elastic test, the cone, and for the
// lanes the cone does not take the cap's Newton iteration and the tangent ring. A lane with a non-finite trial is marked -1 and left unchanged.
[[gnu::always_inline]] inline void ReturnLanes(const LaneConstants& c, ReturnGroup& g) {
  const Real4 a0 = Load4(g.tau[0]), a1 = Load4(g.tau[1]), a2 = Load4(g.tau[2]);
  const Real4 I1 = (a0 + a1) + a2, mean = I1 / 3.0;
  const Real4 s0 = a0 - mean, s1 = a1 - mean, s2 = a2 - mean;
  const Real4 s_norm = Sqrt4((s0 * s0 + s1 * s1) + s2 * s2);
  const Real4 I_t = Splat4(c.I1_tangent), zero = Splat4(0.0);
  const Real4 F1 = (s_norm + c.rho_f * I1) - c.yield_stress;                 // F1 (3.101)
  const Real4 F2 = Sqrt4(s_norm * s_norm + I1 * I1 / 3.0) - c.radius;         // F2
  const Mask4 elastic = (I1 <= I_t ? F1 : F2) <= zero;
  // Cone return (3.88)-(3.91): dgamma = F1 / (2G + 9K varrho_F varrho_G).
  const Real4 dgamma = F1 / c.denominator;
  const Real4 I1_new = I1 - c.volume_factor * dgamma;  // (3.89)
  const Real4 shrink = (2.0 * c.G) * dgamma;
  const Mask4 cone = ~elastic & (F1 > zero) & (s_norm - shrink >= zero) & (I1_new <= I_t);
  const Real4 factor = 1.0 - shrink / s_norm, mean_new = I1_new / 3.0;
  Real4 r0 = s0 * factor + mean_new, r1 = s1 * factor + mean_new;
  Real4 r2 = s2 * factor + mean_new;
  // The cap and the ring for the finite lanes that neither test took (SmoothCapReturn's scalar
  // Newton on x = dgamma / R_t, each lane iterating until its own test stops it).
  const Mask4 finite = ((I1 - I1) == zero) & ((s_norm - s_norm) == zero);
  const Mask4 rest = ~elastic & ~cone & finite;
  Mask4 on_cap = rest & 0;
  if (rest[0] | rest[1] | rest[2] | rest[3]) {
    const Real g2 = 2.0 * c.G, k3 = 3.0 * c.K;
    const Real4 abs_I1 = I1 < zero ? -I1 : I1;  // std::abs
    const Real4 x_s = (s_norm / c.radius - 1.0) / g2, x_I = (abs_I1 / c.radius_sqrt3 - 1.0) / k3;
    Real4 x = zero;  // std::max({0, x_s, x_I}): the first largest
    x = x < x_s ? x_s : x;
    x = x < x_I ? x_I : x;
    Mask4 active = rest;
    const Real4 sn2 = s_norm * s_norm, I12 = I1 * I1;
    for (int it = 0; it < 100 && (active[0] | active[1] | active[2] | active[3]); ++it) {
      const Real4 a = 1.0 + g2 * x, b = 1.0 + k3 * x;
      const Real4 phi = (sn2 / (a * a) + I12 / ((3.0 * b) * b)) - c.radius * c.radius;
      const Real4 dphi = (-4.0 * c.G) * s_norm * s_norm / ((a * a) * a) -
                         (2.0 * c.K) * I1 * I1 / ((b * b) * b);
      active &= ~(dphi >= zero);
      const Real4 step = -phi / dphi;
      x = active ? x + step : x;
      const Real4 abs_step = step < zero ? -step : step;
      const Real4 floor = x < 1e-300 ? Splat4(1e-300) : x;  // std::max(x, 1e-300)
      active &= ~(abs_step <= 1e-15 * floor);
    }
    const Real4 I1_cap = I1 / (1.0 + k3 * x);
    on_cap = rest & (I1_cap >= I_t);
    const Real4 d = 1.0 + g2 * x;
    const Real4 scale = c.radius / Sqrt4(sn2 / (d * d) + I1_cap * I1_cap / 3.0);
    const Real4 mean_cap = I1_cap / 3.0;
    // The tangent ring (I1 = I_t, ||s|| = ||s||_t) in the direction of s_tr.
    const Real4 mean_t = Splat4(c.I1_tangent / 3.0);
    const Mask4 has_s = s_norm > zero;
    const Real4 n0 = has_s ? s0 / s_norm : zero, n1 = has_s ? s1 / s_norm : zero;
    const Real4 n2 = has_s ? s2 / s_norm : zero;
    r0 = rest ? (on_cap ? (s0 / d + mean_cap) * scale : c.s_tangent * n0 + mean_t) : r0;
    r1 = rest ? (on_cap ? (s1 / d + mean_cap) * scale : c.s_tangent * n1 + mean_t) : r1;
    r2 = rest ? (on_cap ? (s2 / d + mean_cap) * scale : c.s_tangent * n2 + mean_t) : r2;
  }
  const Mask4 plastic = cone | rest;
  Store4(g.tau[0], plastic ? r0 : a0);
  Store4(g.tau[1], plastic ? r1 : a1);
  Store4(g.tau[2], plastic ? r2 : a2);
  // eps_tr - [D^e_d] tau (HenckyStrain, (3.47)): the plastic increment in principal space.
  const Real4 tr = (r0 + r1) + r2, vol = tr / (9.0 * c.K), third = tr / 3.0;
  const Real g2 = 2.0 * c.G;
  const Real4 d0 = Load4(g.eps[0]) - (vol + (r0 - third) / g2);
  const Real4 d1 = Load4(g.eps[1]) - (vol + (r1 - third) / g2);
  const Real4 d2 = Load4(g.eps[2]) - (vol + (r2 - third) / g2);
  const Real4 d_sum = (d0 + d1) + d2, d_mean = d_sum / 3.0;
  const Real4 e0 = d0 - d_mean, e1 = d1 - d_mean, e2 = d2 - d_mean;
  Store4(g.d_strain, Sqrt4((e0 * e0 + e1 * e1) + e2 * e2));
  Store4(g.d_volume, d_sum);
  const Real4 other = rest ? (on_cap ? Splat4(2.0) : Splat4(3.0)) : Splat4(-1.0);
  Store4(g.region, elastic ? zero : (cone ? Splat4(1.0) : other));
}

void ReturnPortable(const LaneConstants& c, ReturnGroup& g) { ReturnLanes(c, g); }

#if SURGE_HAVE_WIDE_SIMD
SURGE_TARGET_WIDE void ReturnWide(const LaneConstants& c, ReturnGroup& g) {
  ReturnLanes(c, g);
#if !defined(__clang__)
  _mm256_zeroupper();  // GCC 12 leaves the upper halves dirty (see SymmetricEigen4)
#endif
}
#endif

// PlasticUpdate's body after the trial state (Table 3.4, steps 5-6).
void UpdateFromTrial(const SmoothCapDruckerPragerParams& p, const HenckyTrial& t, Real J,
                     Mat3& elastic_b, History& h, Mat3& stress) {
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

}  // namespace

void PlasticUpdate(const SmoothCapDruckerPragerParams& p, const Mat3& f, Real J, Mat3& elastic_b,
                   History& h, Mat3& stress) {
  const HenckyTrial t = HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b);
  PlasticUpdate(p, f, t, J, elastic_b, h, stress);
}

void PlasticUpdate(const SmoothCapDruckerPragerParams& p, const Mat3&, const HenckyTrial& t,
                   Real J, Mat3& elastic_b, History& h, Mat3& stress) {
  UpdateFromTrial(p, t, J, elastic_b, h, stress);
}

void PlasticUpdate4(const SmoothCapDruckerPragerParams& p, const HenckyTrial* t, const Real* J,
                    Mat3* elastic_b, History* h, Mat3* stress) {
  ReturnGroup g;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 3; ++i) {
      g.tau[i][k] = t[k].tau(i);
      g.eps[i][k] = t[k].eps(i);
    }
  const LaneConstants c = LaneConstantsOf(p);
#if SURGE_HAVE_WIDE_SIMD
  WideSimd() ? ReturnWide(c, g) : ReturnPortable(c, g);
#else
  ReturnPortable(c, g);
#endif
  Vec3 tau[4];
  unsigned lanes = 0;
  for (int k = 0; k < 4; ++k) {
    const int region = int(g.region[k]);
    if (region < 0) {  // a non-finite trial: the scalar return
      UpdateFromTrial(p, t[k], J[k], elastic_b[k], h[k], stress[k]);
      continue;
    }
    h[k][kScdpRegion] = region;
    if (region != 0) {
      h[k][kScdpPlasticStrain] += g.d_strain[k];
      h[k][kScdpPlasticVolume] += g.d_volume[k];
    }
    tau[k] = Vec3(g.tau[0][k], g.tau[1][k], g.tau[2][k]);
    lanes |= 1u << k;
  }
  // Table 3.4, 5(c)-(d) lane by lane: a four-lane finish (tried) was no faster, its exponentials
  // and transpositions being most of its work.
  for (int k = 0; k < 4; ++k)
    if (lanes & (1u << k))
      HenckyFinish(t[k], p.bulk_modulus, p.shear_modulus, tau[k], J[k], elastic_b[k], stress[k]);
}

}  // namespace surge

// Dense snow (cohesive modified Cam-clay, Gaume et al. 2018, Methods): Hencky trial state, an
// associative return solved implicitly for the updated consolidation pressure p0, Hencky finish
// (Mast 2013 Table 3.4; spec §2.0-§2.1, errata 1 and 2 of spec §9 applied through hencky.h).
//
// Notation: p = -tr(tau)/3 (compression positive), s = dev tau, q = sqrt(3/2)|s|; with Hencky
// elasticity p = -K tr(eps_e) and q = 3G sqrt(2/3)|dev eps_e|.
#include "materials/snow.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "materials/hencky.h"

namespace surge {
namespace {

const Real kSqrtThreeHalves = std::sqrt(1.5);

// y(p, q; p0) = (1 + 2 beta) q^2 + M^2 (p + beta p0)(p - p0) (Gaume et al. 2018, Methods).
Real Yield(const SnowParams& m, Real p, Real q, Real p0) {
  const Real beta = m.cohesion_ratio, M = m.critical_state_slope;
  return (1 + 2 * beta) * q * q + M * M * (p + beta * p0) * (p - p0);
}

// Root of fn on [a, b] where fa = fn(a) and fb = fn(b) differ in sign (or one is zero): Illinois
// regula falsi (superlinear, stays bracketed). Stops when the bracket is narrower than xtol.
template <class Fn>
Real SolveBracketed(const Fn& fn, Real a, Real b, Real fa, Real fb, Real xtol) {
  if (fa == 0) return a;
  if (fb == 0) return b;
  int side = 0;
  for (int it = 0; it < 200 && std::abs(b - a) > xtol; ++it) {
    Real c = (a * fb - b * fa) / (fb - fa);
    if (!(c > std::min(a, b) && c < std::max(a, b))) c = 0.5 * (a + b);
    const Real fc = fn(c);
    if (fc == 0) return c;
    if ((fc > 0) == (fb > 0)) {
      b = c;
      fb = fc;
      if (side == -1) fa *= 0.5;
      side = -1;
    } else {
      a = c;
      fa = fc;
      if (side == 1) fb *= 0.5;
      side = 1;
    }
  }
  return std::abs(fa) < std::abs(fb) ? a : b;
}

struct SnowReturn {
  Real p;      // mean stress after the return [Pa]
  Real q;      // equivalent shear stress after the return [Pa]
  Real alpha;  // volumetric plastic strain after the return [-]
};

// Associative, backward-Euler return of a trial state (p_tr, q_tr) outside the surface of
// p0(alpha_n). The flow eps^p = dgamma dy/dtau gives, with Hencky elasticity,
//   p = p_tr - K dgamma M^2 (2p - (1 - beta) p0)          (volumetric, d eps_v^p = -dgamma y_p)
//   q = q_tr / (1 + 6 G (1 + 2 beta) dgamma)              (deviatoric, y_q = 2 (1 + 2 beta) q)
//   alpha = alpha_n + (p - p_tr) / K                       (alpha = eps_v^p accumulates)
//   y(p, q; p0(alpha)) = 0                                 (on the updated surface)
// Eliminating dgamma and alpha leaves one equation R(p) = 0 in p. D(p) = 2p - (1 - beta) p0(p)
// increases with p (dD/dp >= 2), so its root p_d (top of the updated ellipse, where dgamma -> oo
// and q -> 0) is unique; R > 0 at p_tr and R < 0 at p_d, so the root lies between them: on the
// compaction side p_d < p < p_tr, on the dilation side p_tr < p < p_d.
SnowReturn ReturnToSurface(const SnowParams& m, Real p_tr, Real q_tr, Real alpha_n) {
  const Real K = m.bulk_modulus, G = m.shear_modulus, beta = m.cohesion_ratio;
  const Real M2 = m.critical_state_slope * m.critical_state_slope;
  const Real p0_n = SnowConsolidationPressure(m, alpha_n);
  auto alpha_of = [&](Real p) { return alpha_n + (p - p_tr) / K; };  // p - p_tr = K d eps_v^p
  auto p0_of = [&](Real p) { return SnowConsolidationPressure(m, alpha_of(p)); };
  auto D = [&](Real p) { return 2 * p - (1 - beta) * p0_of(p); };  // y_p / M^2
  auto q_of = [&](Real p) {
    const Real d = D(p);
    if (d == 0) return Real(0);
    const Real w = 6 * G * (1 + 2 * beta) * (p_tr - p) / (K * M2 * d);  // 6G(1+2beta) dgamma
    return std::isfinite(w) ? q_tr / (1 + w) : Real(0);
  };
  auto R = [&](Real p) { return Yield(m, p, q_of(p), p0_of(p)); };

  const Real xtol = 1e-15 * std::max({std::abs(p_tr), q_tr, p0_n,
                                      std::numeric_limits<Real>::min()});
  const Real d_tr = D(p_tr);
  if (d_tr == 0) {  // trial at the top: purely deviatoric flow, p and p0 unchanged
    const Real q2 = -M2 * (p_tr + beta * p0_n) * (p_tr - p0_n) / (1 + 2 * beta);
    return {p_tr, std::sqrt(std::max(q2, Real(0))), alpha_n};
  }
  Real p_d;
  if (d_tr > 0) {  // compaction side: D(0) = -(1 - beta) p0 <= 0
    p_d = SolveBracketed(D, Real(0), p_tr, D(0), d_tr, xtol);
  } else {  // dilation side: p0 only softens for p > p_tr, so D((1 - beta) p0_n / 2) >= 0
    const Real lo = std::max(p_tr, Real(0)), hi = 0.5 * (1 - beta) * p0_n;
    p_d = SolveBracketed(D, lo, hi, D(lo), D(hi), xtol);
  }
  const Real r_d = Yield(m, p_d, 0, p0_of(p_d));  // q = 0 at p_d; < 0 unless p0(p_d) = 0
  const Real r_tr = Yield(m, p_tr, q_tr, p0_n);   // > 0: the trial state is outside
  const Real p = d_tr > 0 ? SolveBracketed(R, p_d, p_tr, r_d, r_tr, xtol)
                          : SolveBracketed(R, p_tr, p_d, r_tr, r_d, xtol);
  // At the root both q_of(p) and the surface's q, y(p, q; p0(p)) = 0, are exact, but each is
  // ill-conditioned somewhere: near the top of the ellipse (the critical state, dgamma -> oo)
  // q_of is 0/0 and amplifies the round-off of p by 1/D(p); near the tips (q -> 0) the surface's
  // q is the square root of round-off. The smaller of the two is the well-conditioned one in both
  // places and never lies outside the updated surface.
  const Real p0 = p0_of(p);
  const Real q2 = -M2 * (p + beta * p0) * (p - p0) / (1 + 2 * beta);
  return {p, std::min(q_of(p), std::sqrt(std::max(q2, Real(0)))), alpha_of(p)};
}

// (p, q) of a stress tensor.
void Invariants(const Mat3& tau, Real& p, Real& q) {
  p = -tau.trace() / 3;
  q = kSqrtThreeHalves * Dev(tau).norm();
}

}  // namespace

Real SnowConsolidationPressure(const SnowParams& m, Real alpha) {
  // p0 = K sinh(xi max(-alpha, 0)) (Gaume et al. 2018, Methods; K is the bulk modulus).
  return m.bulk_modulus * std::sinh(m.hardening_factor * std::max(-alpha, Real(0)));
}

Real SnowYieldFunction(const SnowParams& m, const Mat3& tau, const History& h) {
  Real p, q;
  Invariants(tau, p, q);
  return Yield(m, p, q, h[kSnowConsolidation]);
}

Real SnowYieldScale(const SnowParams& m, const Mat3& tau, const History& h) {
  Real p, q;
  Invariants(tau, p, q);
  const Real beta = m.cohesion_ratio, M = m.critical_state_slope, p0 = h[kSnowConsolidation];
  return (1 + 2 * beta) * q * q + M * M * (std::abs(p) + beta * p0) * (std::abs(p) + p0);
}

Real SnowCriticalStateRatio(const SnowParams& m) {
  // y = 0 at p = (1 - beta) p0 / 2, where dy/dp = 0: q^2 (1 + 2 beta) = M^2 p^2 (1+beta)^2/(1-beta)^2.
  const Real beta = m.cohesion_ratio;
  return m.critical_state_slope * (1 + beta) / ((1 - beta) * std::sqrt(1 + 2 * beta));
}

// Table 3.4 with the snow return in principal space. Elasticity and flow are isotropic, so the
// return keeps the trial eigenvectors and the direction of the trial deviator.
void SnowUpdate(const SnowParams& m, const Mat3& f, Real J, Mat3& elastic_b, History& h,
                Mat3& stress) {
  SnowUpdate(m, HenckyTrialState(m.bulk_modulus, m.shear_modulus, f, elastic_b), J, elastic_b, h,
             stress);
}

void SnowUpdate(const SnowParams& m, const HenckyTrial& t, Real J, Mat3& elastic_b, History& h,
                Mat3& stress) {
  const Real K = m.bulk_modulus, G = m.shear_modulus;  // t: Table 3.4 steps 1-4
  const Real p_tr = -t.tau.sum() / 3;
  const Vec3 s_tr = (t.tau.array() + p_tr).matrix();
  const Real q_tr = kSqrtThreeHalves * s_tr.norm();
  const Real alpha_n = h[kSnowVolumetricPlastic];
  const Real p0_n = SnowConsolidationPressure(m, alpha_n);
  h[kSnowConsolidation] = p0_n;

  if (Yield(m, p_tr, q_tr, p0_n) <= 0) {  // elastic: b^e_{n+1} = b^e_tr
    elastic_b = FromPrincipal(t.Q, (2.0 * t.eps).array().exp().matrix());
    stress = FromPrincipal(t.Q, t.tau) / J;  // (3.37)
    return;
  }
  const SnowReturn r = ReturnToSurface(m, p_tr, q_tr, alpha_n);
  const Vec3 s = q_tr > 0 ? Vec3(s_tr * (r.q / q_tr)) : Vec3::Zero();  // radial in the pi-plane
  const Vec3 tau = (s.array() - r.p).matrix();
  h[kSnowPlasticStrain] += (q_tr - r.q) / (3 * G);  // |dev d eps^p| sqrt(2/3) = (q_tr - q)/(3G)
  h[kSnowVolumetricPlastic] = r.alpha;
  h[kSnowConsolidation] = SnowConsolidationPressure(m, r.alpha);
  HenckyFinish(t, K, G, tau, J, elastic_b, stress);  // Table 3.4 5(c)-(d)
}

void InitialPlasticHistory(const SnowParams& m, const Mat3& stress, History& h) {
  Real p, q;
  Invariants(stress, p, q);  // tau = sigma at F = I
  const Real beta = m.cohesion_ratio, M2 = m.critical_state_slope * m.critical_state_slope;
  // Smallest p0 with y(p, q; p0) <= 0: the positive root of
  // beta p0^2 + (1 - beta) p p0 - p^2 - (1 + 2 beta) q^2 / M^2 = 0.
  const Real c = p * p + (1 + 2 * beta) * q * q / M2;
  Real p0_needed = 0;
  if (beta > 0) {
    p0_needed = (-(1 - beta) * p + std::sqrt((1 - beta) * (1 - beta) * p * p + 4 * beta * c)) /
                (2 * beta);
  } else if (p > 0) {
    p0_needed = c / p;
  }
  const Real p0 = std::max(m.consolidation_pressure, p0_needed);
  h[kSnowVolumetricPlastic] = -std::asinh(p0 / m.bulk_modulus) / m.hardening_factor;
  h[kSnowConsolidation] = SnowConsolidationPressure(m, h[kSnowVolumetricPlastic]);  // p0, to round-off
}

}  // namespace surge

// Matsuoka-Nakai (and MN with a Drucker-Prager potential) at finite strain:
// Hencky trial state, semi-implicit principal-space return (Tu, Andrade & Chen
// 2009; Mast 2013 (3.48)-(3.51)), Hencky finish (Table 3.4), then the angle
// update (3.112)-(3.116) (spec §2.7-§2.8).
//
// Notation: tau are principal Kirchhoff stresses, tau' = tau - c_F 1 the
// shifted ones, and I1', I2', I3' their invariants (3.55)-(3.57). F = 6 kappa
// I3' - 6 I1' I2' is cubic in tau', so the Newton works with the
// homogeneous-degree-1 F / (2 kappa |tau'|^2) (stress units; spec §2.8 [REC])
// and the tests measure the relative yield error |F| / (6 (kappa |I3'| + |I1'
// I2'|)) (MatsuokaNakaiYieldScale).
#include "materials/matsuoka_nakai.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "materials/friction_angles.h"
#include "materials/hencky.h"

namespace surge {
namespace {

using Vec4 = Eigen::Matrix<Real, 4, 1>;
using Mat4 = Eigen::Matrix<Real, 4, 4>;

constexpr int kMaxNewtonIterations = 50;
constexpr int kMaxBacktracks = 40;
constexpr Real kNewtonTolerance =
    1e-12; // on |r|_inf / p_ref, every row in stress units
constexpr Real kMaxAngleDeg = 89; // guard: kappa -> infinity as phi -> 90 deg

Vec3 Shifted(const Vec3 &tau, Real c) { return (tau.array() - c).matrix(); }

Real SecondInvariant(const Vec3 &s) {
  return s[0] * s[1] + s[0] * s[2] + s[1] * s[2];
}

// [D^e_d]_IJ = 1/(9K) + (delta_IJ - 1/3) / (2G) (spec §2.0, compliance (3.47)).
Mat3 PrincipalCompliance(Real K, Real G) {
  Mat3 D = Mat3::Constant(1.0 / (9.0 * K) - 1.0 / (6.0 * G));
  D.diagonal().array() += 1.0 / (2.0 * G);
  return D;
}

// Plastic potential of the return: the MN function (3.123) with kappa_G (3.124)
// and shift c_G, or the Drucker-Prager cone G = ||s|| + varrho_G I1
// (3.108)-(3.109). The MN gradient is used normalised, g = grad G / |grad G|
// (dgamma absorbs the scale of G; the cubic's gradient grows quadratically with
// the stress, which makes the unnormalised Newton needlessly nonlinear).
struct Potential {
  bool drucker_prager = false;
  Real kappa = 9; // kappa_G (MN)
  Real shift = 0; // c_G (MN) [Pa]
  Real slope = 0; // varrho_G (DP)
  Real s_floor =
      0; // smallest ||s|| (DP) or |grad G| (MN) used in the derivatives

  Vec3 Gradient(const Vec3 &tau) const {
    if (!drucker_prager) {
      const Vec3 g = MatsuokaNakaiGradient(kappa, shift, tau); // (3.125)
      return g / std::max(g.norm(), s_floor);
    }
    const Vec3 s = (tau.array() - tau.sum() / 3.0).matrix();
    return s / std::max(s.norm(), s_floor) +
           Vec3::Constant(slope); // (3.110)-(3.111), (A.17)
  }
  Mat3 Hessian(const Vec3 &tau) const {
    if (!drucker_prager) {
      // d(g/|g|) = (I - n n^T) d2G / |g| with d2G of (3.127).
      const Vec3 g = MatsuokaNakaiGradient(kappa, shift, tau);
      const Real norm = std::max(g.norm(), s_floor);
      const Vec3 n = g / norm;
      return (Mat3::Identity() - n * n.transpose()) *
             MatsuokaNakaiHessian(kappa, shift, tau) / norm;
    }
    // d2G/dtau_I dtau_J = (delta_IJ - 1/3 - n_I n_J) / ||s|| (spec §2.7, from
    // (A.17)).
    const Vec3 s = (tau.array() - tau.sum() / 3.0).matrix();
    const Real norm = std::max(s.norm(), s_floor);
    const Vec3 n = s / norm;
    return (Mat3::Identity() - Mat3::Constant(1.0 / 3.0) - n * n.transpose()) /
           norm;
  }
};

// The frozen data of one return (semi-implicit: angles from step n).
struct ReturnProblem {
  Real K, G, cohesion, kappa_f, p_ref;
  Mat3 D; // [D^e_d]
  Vec3 eps_tr;
  Potential potential;

  bool Admissible(const Vec3 &tau) const {
    return Shifted(tau, cohesion).maxCoeff() < 0;
  }

  // Yield row in the homogeneous-degree-1 form F_h = F / (2 kappa_F |tau'|^2)
  // [Pa] (spec §2.8 [REC] scaling): linear along rays from the apex, same zero
  // set as F inside the octant.
  Real YieldRow(const Vec3 &tau) const {
    const Vec3 t = Shifted(tau, cohesion);
    return MatsuokaNakaiFunction(kappa_f, cohesion, tau) /
           (2.0 * kappa_f * t.squaredNorm());
  }
  Vec3 YieldRowGradient(const Vec3 &tau) const {
    const Vec3 t = Shifted(tau, cohesion);
    const Real n2 = t.squaredNorm();
    return (MatsuokaNakaiGradient(kappa_f, cohesion, tau) -
            MatsuokaNakaiFunction(kappa_f, cohesion, tau) * 2.0 * t / n2) /
           (2.0 * kappa_f * n2);
  }
  // r = {2G ([D^e_d] tau - eps_tr + dgamma g); F_h} (3.50), all rows in Pa.
  Vec4 Residual(const Vec3 &tau, Real dgamma) const {
    Vec4 r;
    r.head<3>() =
        2.0 * G * (D * tau - eps_tr + dgamma * potential.Gradient(tau));
    r[3] = YieldRow(tau);
    return r;
  }
  // J = [[D + dgamma d2G, g], [f^T, 0]] (3.51), rows scaled as in Residual.
  Mat4 Jacobian(const Vec3 &tau, Real dgamma) const {
    Mat4 J = Mat4::Zero();
    J.topLeftCorner<3, 3>() = 2.0 * G * (D + dgamma * potential.Hessian(tau));
    J.topRightCorner<3, 1>() = 2.0 * G * potential.Gradient(tau);
    J.bottomLeftCorner<1, 3>() = YieldRowGradient(tau).transpose();
    return J;
  }
};

// Newton (Table 3.2) with a backtracking line search on |r|^2 that keeps the
// iterate inside the compressive octant of the shifted stress (where F <= 0 is
// the admissible side, spec §2.8). Returns true on convergence with dgamma >=
// 0.
bool SolveNewton(const ReturnProblem &pb, Vec3 &tau, Real &dgamma,
                 int &iterations) {
  const Real tol = kNewtonTolerance * pb.p_ref;
  Vec4 r = pb.Residual(tau, dgamma);
  for (int it = 0; it < kMaxNewtonIterations; ++it) {
    if (r.cwiseAbs().maxCoeff() <= tol)
      return dgamma >= 0;
    ++iterations;
    const Eigen::FullPivLU<Mat4> lu(pb.Jacobian(tau, dgamma));
    if (!lu.isInvertible())
      return false;
    const Vec4 step = -lu.solve(r);
    const Real merit = r.squaredNorm();
    Real alpha = 1;
    bool accepted = false;
    for (int b = 0; b < kMaxBacktracks; ++b, alpha *= 0.5) {
      const Vec3 tau_new = tau + alpha * step.head<3>();
      if (!pb.Admissible(tau_new))
        continue;
      const Real dgamma_new = dgamma + alpha * step[3];
      const Vec4 r_new = pb.Residual(tau_new, dgamma_new);
      if (r_new.squaredNorm() <= (1.0 - 1e-4 * alpha) * merit ||
          r_new.cwiseAbs().maxCoeff() <= tol) {
        tau = tau_new;
        dgamma = dgamma_new;
        r = r_new;
        accepted = true;
        break;
      }
    }
    if (!accepted)
      return false;
  }
  return r.cwiseAbs().maxCoeff() <= tol && dgamma >= 0;
}

// Closed-form return to the Drucker-Prager cone through the MN compression
// meridian (the outer cone: varrho_F of (3.107), apex at the MN apex tau = c 1)
// with potential slope varrho_G: dgamma = F_tr / (2G + 9K varrho_F varrho_G), s
// = s_tr - 2G dgamma n, I1 = I1_tr - 9K varrho_G dgamma ((3.88)-(3.91), spec
// §2.5 with H = k = 0). Returns false when it passes the apex.
bool DruckerPragerConeReturn(const ReturnProblem &pb, const Vec3 &tau_tr,
                             Real rho_f, Real rho_g, Vec3 &tau, Real &dgamma) {
  const Real i1_tr = tau_tr.sum();
  const Vec3 s_tr = (tau_tr.array() - i1_tr / 3.0).matrix();
  const Real s_norm = s_tr.norm();
  const Real f_tr =
      s_norm + rho_f * (i1_tr - 3.0 * pb.cohesion); // (3.106), apex I1 = 3 c_F
  dgamma = f_tr / (2.0 * pb.G + 9.0 * pb.K * rho_f * rho_g);
  const Real i1 = i1_tr - 9.0 * pb.K * rho_g * dgamma; // (3.89)
  if (s_norm - 2.0 * pb.G * dgamma <= 0 || i1 >= 3.0 * pb.cohesion)
    return false;
  tau = (s_tr * (1.0 - 2.0 * pb.G * dgamma / s_norm)).array() +
        i1 / 3.0; // (3.90)
  return true;
}

// Last resort: scale the deviator of `tau` (fixed I1 and Lode angle) onto F = 0
// by bisection; F is negative on the hydrostatic axis of the compressive
// octant.
Vec3 RadialProjection(const ReturnProblem &pb, const Vec3 &tau) {
  const Real mean = tau.sum() / 3.0;
  const Vec3 s = (tau.array() - mean).matrix();
  auto at = [&](Real t) { return Vec3((t * s).array() + mean); };
  auto fn = [&](Real t) {
    return MatsuokaNakaiFunction(pb.kappa_f, pb.cohesion, at(t));
  };
  if (mean >= pb.cohesion)
    return Vec3::Constant(pb.cohesion);
  Real lo = 0, hi = 1;
  if (fn(hi) <= 0 && pb.Admissible(at(hi)))
    return tau;
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const Real mid = 0.5 * (lo + hi);
    (fn(mid) <= 0 && pb.Admissible(at(mid)) ? lo : hi) = mid;
  }
  return at(lo);
}

// Principal values of a symmetric tensor.
Vec3 PrincipalValues(const Mat3 &a) {
  return Eigen::SelfAdjointEigenSolver<Mat3>(Sym(a), Eigen::EigenvaluesOnly)
      .eigenvalues();
}

Real ClampAngle(Real deg) { return std::clamp(deg, Real(0), kMaxAngleDeg); }

// Angles (3.112)-(3.114) at I1 [Pa] and lambda, written into the history.
void StoreAngles(const MatsuokaNakaiParams &p, Real i1, Real lambda,
                 History &h) {
  h[kMnLambda] = lambda;
  h[kMnFrictionAngle] =
      ClampAngle(MobilisedFrictionDeg(p.friction, i1, lambda));  // (3.113)
  h[kMnCriticalAngle] = CriticalFrictionDeg(p.friction, lambda); // (3.114)
  h[kMnDilationAngle] = p.zero_dilation
                            ? 0
                            : DilationAngleDeg(h[kMnFrictionAngle],
                                               h[kMnCriticalAngle]); // (3.112)
}

} // namespace

Real MatsuokaNakaiKappa(Real phi_deg) {
  const Real s2 = std::pow(std::sin(Radians(phi_deg)), 2);
  return (s2 - 9.0) / (s2 - 1.0); // (3.121), (3.124)
}

Real MatsuokaNakaiFunction(Real kappa, Real c, const Vec3 &tau) {
  const Vec3 t = Shifted(tau, c); // (3.55)-(3.57)
  return 6.0 * kappa * t.prod() -
         6.0 * t.sum() * SecondInvariant(t); // (3.120) = (3.122)
}

Vec3 MatsuokaNakaiGradient(Real kappa, Real c, const Vec3 &tau) {
  // dI1'/dtau_I = 1, dI2'/dtau_I = I1' - tau'_I, dI3'/dtau_I = tau'_J tau'_K
  // (J, K != I), (3.60)- (3.68); the sum equals (3.125) (spec §2.8,
  // sympy-checked).
  const Vec3 t = Shifted(tau, c);
  const Real i1 = t.sum(), i2 = SecondInvariant(t);
  Vec3 g;
  for (int I = 0; I < 3; ++I) {
    const Real others =
        t[(I + 1) % 3] * t[(I + 2) % 3]; // I3' / tau'_I without the division
    g[I] = 6.0 * (kappa * others - i2 - i1 * (i1 - t[I]));
  }
  return g;
}

Mat3 MatsuokaNakaiHessian(Real kappa, Real c, const Vec3 &tau) {
  // d2F = 6 [kappa (1 - delta_IJ) tau'_K - 3 I1' + tau'_I + tau'_J + I1'
  // delta_IJ], K the third index: (3.127) in shifted values, with 6 kappa I3' /
  // (tau'_I tau'_J) = 6 kappa tau'_K.
  const Vec3 t = Shifted(tau, c);
  const Real i1 = t.sum();
  Mat3 H;
  for (int I = 0; I < 3; ++I) {
    for (int J = 0; J < 3; ++J) {
      const Real cross = I == J ? i1 : kappa * t[3 - I - J];
      H(I, J) = 6.0 * (cross - 3.0 * i1 + t[I] + t[J]);
    }
  }
  return H;
}

Real MatsuokaNakaiGradientTrace(Real kappa, Real c, const Vec3 &tau) {
  const Real i1 = tau.sum(), i2 = SecondInvariant(tau);
  // (3.128) with the I2 coefficient (6 kappa - 18) of erratum 8 (spec §9).
  return (6.0 * kappa - 18.0) * i2 - 12.0 * i1 * i1 +
         12.0 * c * (9.0 - kappa) * i1 + c * c * (18.0 * kappa - 162.0);
}

Real MatsuokaNakaiYieldFunction(const MatsuokaNakaiParams &p, const Mat3 &tau,
                                const History &h) {
  return MatsuokaNakaiFunction(MatsuokaNakaiKappa(h[kMnFrictionAngle]),
                               p.cohesion, PrincipalValues(tau));
}

Real MatsuokaNakaiYieldScale(const MatsuokaNakaiParams &p, const Mat3 &tau,
                             const History &h) {
  const Vec3 t = Shifted(PrincipalValues(tau), p.cohesion);
  const Real kappa = MatsuokaNakaiKappa(h[kMnFrictionAngle]);
  return 6.0 *
         (kappa * std::abs(t.prod()) + std::abs(t.sum() * SecondInvariant(t)));
}

MatsuokaNakaiReturn MatsuokaNakaiReturnMap(const MatsuokaNakaiParams &p,
                                           const Vec3 &eps_tr,
                                           const Vec3 &tau_tr, Real phi_f_deg,
                                           Real psi_g_deg) {
  MatsuokaNakaiReturn out;
  const Real K = p.bulk_modulus, G = p.shear_modulus, c = p.cohesion;
  const Vec3 shifted_tr = Shifted(tau_tr, c);
  // Tension cutoff (spec §2.8 [REC], the cutoff surface of §2.5): a trial state
  // with a shifted principal stress >= 0 returns to the apex tau = c_F 1.
  if (shifted_tr.maxCoeff() >= 0) {
    out.apex = true;
    out.tau = Vec3::Constant(c);
    out.plastic_strain = eps_tr - HenckyStrain(K, G, out.tau);
    return out;
  }
  ReturnProblem pb;
  pb.K = K;
  pb.G = G;
  pb.cohesion = c;
  pb.kappa_f = MatsuokaNakaiKappa(phi_f_deg);
  pb.D = PrincipalCompliance(K, G);
  pb.eps_tr = eps_tr;
  const Vec3 s_tr = (tau_tr.array() - tau_tr.sum() / 3.0).matrix();
  pb.p_ref = std::max(-shifted_tr.sum() / 3.0, s_tr.norm());
  const Real rho_g = DruckerPragerSlope(Radians(psi_g_deg)); // (3.109)
  if (p.potential == MatsuokaNakaiPotential::kDruckerPrager) {
    pb.potential.drucker_prager = true;
    pb.potential.slope = rho_g;
    pb.potential.s_floor = 1e-14 * pb.p_ref;
  } else {
    // c_G = c_F: see docs/materials.md ("Matsuoka-Nakai"): the seed's analysis
    // (3.128)-(3.129) and its results (Fig. 3.9b) use a finite c_G; a c_G that
    // puts G through the current point diverges as psi_G -> 0.
    pb.potential.kappa = MatsuokaNakaiKappa(psi_g_deg); // (3.124)
    pb.potential.shift = c;
    pb.potential.s_floor = 1e-300;
  }

  // First attempt: Newton from the trial state, dgamma = 0 (spec §2.8 [REC]).
  Vec3 tau = tau_tr;
  Real dgamma = 0;
  bool ok = SolveNewton(pb, tau, dgamma, out.iterations);
  if (!ok) {
    // Fallback: restart from the return to the outer DP cone (spec §2.8 [REC]),
    // with dgamma the least-squares fit of the strain rows there.
    out.fallback = true;
    const Real rho_f = DruckerPragerSlope(Radians(phi_f_deg)); // (3.107)
    Vec3 tau_dp;
    Real dgamma_dp;
    if (!DruckerPragerConeReturn(pb, tau_tr, rho_f, rho_g, tau_dp, dgamma_dp)) {
      out.apex = true; // the cone return passes the apex: so does the MN return
      out.tau = Vec3::Constant(c);
      out.plastic_strain = eps_tr - HenckyStrain(K, G, out.tau);
      return out;
    }
    tau = tau_dp;
    const Vec3 g = pb.potential.Gradient(tau);
    dgamma = std::max(Real(0), g.dot(eps_tr - pb.D * tau) / g.squaredNorm());
    ok = pb.Admissible(tau) && SolveNewton(pb, tau, dgamma, out.iterations);
    if (!ok) {
      out.converged = false;
      tau = RadialProjection(pb, tau_dp);
    }
  }
  out.tau = tau;
  out.plastic_strain =
      eps_tr - pb.D * tau; // = dgamma g at convergence (3.50), row 1
  return out;
}

// Table 3.4 with the semi-implicit MN return, then the angle update of spec
// §2.7 step 4-5.
void MatsuokaNakaiUpdate(const MatsuokaNakaiParams &p, const Mat3 &f, Real J,
                         Mat3 &elastic_b, History &h, Mat3 &stress) {
  MatsuokaNakaiUpdate(
      p, HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b), J,
      elastic_b, h, stress);
}

void MatsuokaNakaiUpdate(const MatsuokaNakaiParams &p, const HenckyTrial &t,
                         Real J, Mat3 &elastic_b, History &h, Mat3 &stress) {
  const Real K = p.bulk_modulus, G = p.shear_modulus; // t: Table 3.4 steps 1-4
  const Real phi_f = h[kMnFrictionAngle], psi_g = h[kMnDilationAngle];
  if (Shifted(t.tau, p.cohesion).maxCoeff() < 0 &&
      MatsuokaNakaiFunction(MatsuokaNakaiKappa(phi_f), p.cohesion, t.tau) <=
          0) {
    elastic_b = FromPrincipal(
        t.Q, (2.0 * t.eps).array().exp().matrix()); // b^e = b^e_tr
    stress = FromPrincipal(t.Q, t.tau) / J;         // (3.37)
    return;
  }
  const MatsuokaNakaiReturn r =
      MatsuokaNakaiReturnMap(p, t.eps, t.tau, phi_f, psi_g);
  const Vec3 dev_plastic =
      (r.plastic_strain.array() - r.plastic_strain.sum() / 3.0).matrix();
  const Real dlambda =
      dev_plastic.norm(); // |dgamma I_dev : g| (3.116), spec §2.7 [REC]
  h[kMnPlasticStrain] += std::sqrt(2.0 / 3.0) * dlambda;
  h[kMnVolumetricPlastic] += r.plastic_strain.sum();
  HenckyFinish(t, K, G, r.tau, J, elastic_b, stress); // Table 3.4 5(c)-(d)
  // Semi-implicit: the angles of the next step from the converged state (Tu et
  // al. 2009).
  StoreAngles(p, stress.trace(), h[kMnLambda] + dlambda, h);
}

void InitialPlasticHistory(const MatsuokaNakaiParams &p, const Mat3 &stress,
                           History &h) {
  const Real i1 = stress.trace(); // tau = sigma at F = I
  StoreAngles(p, i1, 0, h);
  const Vec3 t = Shifted(PrincipalValues(stress), p.cohesion);
  if (t.maxCoeff() >= 0)
    return; // at or beyond the apex: the first step returns it
  if (MatsuokaNakaiFunction(MatsuokaNakaiKappa(h[kMnFrictionAngle]), 0, t) <= 0)
    return;
  // Mobilised angle of the stress: kappa_m = I1' I2' / I3' (F = 0), sin^2 =
  // (kappa - 9)/(kappa - 1).
  const Real kappa_m = t.sum() * SecondInvariant(t) / t.prod();
  const Real phi_m =
      Degrees(std::asin(std::sqrt((kappa_m - 9.0) / (kappa_m - 1.0))));
  const FrictionCurve &a = p.friction;
  // Hardening branch of (3.113): up to the peak lambda* = 1/a3 + a4/a1 (spec
  // §2.7 [DERIVED]).
  Real hi = 0;
  if (a.a1 > 0 && a.a3 > 0) {
    hi = 1.0 / a.a3 + a.a4 / a.a1;
  } else if (a.a3 > 0) {
    hi = 40.0 /
         a.a3; // a1 = 0: phi_F rises monotonically to a0, within e^-40 here
  }
  auto phi_at = [&](Real lambda) {
    return ClampAngle(MobilisedFrictionDeg(a, i1, lambda));
  };
  Real lo = 0;
  if (phi_at(hi) <= phi_m) {
    lo = hi; // stronger than the peak: start at the peak, the first step
             // returns it
  } else {
    for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
      const Real mid = 0.5 * (lo + hi);
      (phi_at(mid) < phi_m ? lo : hi) = mid;
    }
    lo = hi; // phi_F(hi) >= phi_m: the surface holds the stress
  }
  StoreAngles(p, i1, lo, h);
}

} // namespace surge

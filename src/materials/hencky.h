// Shared pieces of every elastoplastic model in Surge: quadratic-logarithmic (Hencky) elasticity
// in Kirchhoff stress and the principal-space finite-deformation return of Mast (2013) Table 3.4
// (spec seed-algorithms.md §2.0-§2.1; errata 1 and 2 of spec §9 applied).
//
// A model's stress update is
//   HenckyTrial t = HenckyTrialState(K, G, f, b^e_n);       // Table 3.4 steps 1-4
//   Vec3 tau = <the model's return of t.tau in principal space>;
//   HenckyFinish(t, K, G, tau, J, b^e, sigma);               // steps 5(c), 5(d), (3.37)
// so every model shares the spectral decomposition and the bookkeeping of b^e.
#pragma once
#include "core/math.h"

namespace surge {

// Trial state in the eigenbasis of b^e_tr = f b^e_n f^T (3.35).
struct HenckyTrial {
  Mat3 b;    // b^e_tr = f b^e_n f^T (3.35)
  Mat3 Q;    // eigenvectors of b^e_tr (columns): the principal directions n^(i)
  Vec3 eps;  // principal trial Hencky strains eps_i = 1/2 ln b_i (3.34), erratum 2
  Vec3 tau;  // principal trial Kirchhoff stresses [C^e_d] eps (Table 3.4, step 4) [Pa]
};

// Steps 1-4 of Table 3.4. Pre: det f > 0, b^e_n symmetric positive definite.
HenckyTrial HenckyTrialState(Real K, Real G, const Mat3& f, const Mat3& elastic_b);
// The same for two particles of one material, each bitwise equal to HenckyTrialState: the two
// spectral decompositions run side by side (SymmetricEigen2).
void HenckyTrialStates(Real K, Real G, const Mat3& f0, const Mat3& elastic_b0, const Mat3& f1,
                       const Mat3& elastic_b1, HenckyTrial& t0, HenckyTrial& t1);
// The same for four particles (f[k], elastic_b[k] into t[k]): SymmetricEigen4.
void HenckyTrialStates4(Real K, Real G, const Mat3* f, const Mat3* elastic_b, HenckyTrial* t);

// Principal Kirchhoff stress of principal Hencky strains: tau_i = K tr(eps) + 2G (eps_i - tr/3)
// ([C^e_d], spec §2.0, with the factor 2 of erratum 1). Inline, as the two below: they run once
// or twice per particle and step inside every elastoplastic update.
[[gnu::always_inline]] inline Vec3 HenckyStress(Real K, Real G, const Vec3& eps) {
  const Real theta = eps.sum();
  return (2.0 * G * (eps.array() - theta / 3.0) + K * theta).matrix();  // [C^e_d] eps
}

// Inverse: eps_i = tr(tau)/(9K) + (tau_i - tr(tau)/3)/(2G) ([D^e_d], compliance (3.47)).
[[gnu::always_inline]] inline Vec3 HenckyStrain(Real K, Real G, const Vec3& tau) {
  const Real tr = tau.sum();
  return (tr / (9.0 * K) + (tau.array() - tr / 3.0) / (2.0 * G)).matrix();  // [D^e_d] tau
}

// Steps 5(c)-(d) of Table 3.4 and (3.37): b^e_{n+1} = sum exp(2 eps^e_i) m^(i) with
// eps^e = [D^e_d] tau, and sigma_{n+1} = (sum tau_i m^(i)) / J. An elastic step (tau is the
// trial stress, bitwise) keeps b^e_{n+1} = b^e_tr, which the formula reproduces in exact
// arithmetic (eps^e = eps_tr, exp(2 eps_tr,i) = b_i), without the exponentials.
inline void HenckyFinish(const HenckyTrial& trial, Real K, Real G, const Vec3& tau, Real J,
                         Mat3& elastic_b, Mat3& stress);

// Elastic b^e for a Kirchhoff stress: eps_e = D^e : tau (3.47), b^e = exp(2 eps_e) (4.40).
// Used for a prescribed (geostatic) initial stress at F = I, where tau = sigma.
Mat3 ElasticBFromStress(Real K, Real G, const Mat3& tau);

// Stored energy per reference volume [J/m^3]: psi = K/2 (tr eps_e)^2 + G dev eps_e : dev eps_e
// (3.45), written in tau = J sigma as (tr tau)^2 / (18 K) + |dev tau|^2 / (4 G).
Real HenckyEnergy(Real K, Real G, Real J, const Mat3& stress);
// The same from the 6 stored components (the energy record's per-step sum).
Real HenckyEnergy(Real K, Real G, Real J, const SymMat3& stress);

// exp(2 eps) of a symmetric tensor through its spectral decomposition (Mast 2013 (4.40)).
Mat3 ExpTwice(const Mat3& eps);

// Principal values -> tensor in the trial frame: Q diag(v) Q^T.
// Symmetric by construction: the 6 distinct entries sum_k Q_ik v_k Q_jk, mirrored (18
// multiplications against the 36 of the general product).
inline Mat3 FromPrincipal(const Mat3& Q, const Vec3& v) {
  const Vec3 r0 = Q.row(0).transpose().cwiseProduct(v), r1 = Q.row(1).transpose().cwiseProduct(v);
  const Vec3 q0 = Q.row(0).transpose(), q1 = Q.row(1).transpose(), q2 = Q.row(2).transpose();
  const Real m00 = r0.dot(q0), m01 = r0.dot(q1), m02 = r0.dot(q2);
  const Real m11 = r1.dot(q1), m12 = r1.dot(q2);
  const Real m22 = (Q.row(2).transpose().cwiseProduct(v)).dot(q2);
  Mat3 m;
  m << m00, m01, m02,  //
      m01, m11, m12,   //
      m02, m12, m22;
  return m;
}

inline void HenckyFinish(const HenckyTrial& t, Real K, Real G, const Vec3& tau, Real J,
                         Mat3& elastic_b, Mat3& stress) {
  if (tau == t.tau) {
    elastic_b = t.b;  // elastic step: b^e_{n+1} = b^e_tr
  } else {
    const Vec3 eps_e = HenckyStrain(K, G, tau);
    elastic_b = FromPrincipal(t.Q, (2.0 * eps_e).array().exp().matrix());  // Table 3.4, 5(c)
  }
  // 5(d), (3.37): sigma = (sum tau_i m^(i)) / J, its 6 distinct entries divided once each (the
  // matrix is symmetric, so this is bitwise FromPrincipal(Q, tau) / J with 6 divisions, not 9).
  const Mat3 m = FromPrincipal(t.Q, tau);
  const Real s00 = m(0, 0) / J, s01 = m(0, 1) / J, s02 = m(0, 2) / J;
  const Real s11 = m(1, 1) / J, s12 = m(1, 2) / J, s22 = m(2, 2) / J;
  stress << s00, s01, s02,  //
      s01, s11, s12,        //
      s02, s12, s22;
}

}  // namespace surge

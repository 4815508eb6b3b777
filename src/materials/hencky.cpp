// Hencky elasticity and the principal-space return skeleton (Mast 2013 Table 3.4).
#include "materials/hencky.h"

#include <cmath>

#include "materials/symmetric_eigen.h"

namespace surge {

namespace {

// b^e_tr = f b^e_n f^T (3.35): with b^e_n symmetric the result is, so only its 6 distinct
// entries are formed (rows of f b^e_n dotted with rows of f).
[[gnu::always_inline]] inline Mat3 TrialB(const Mat3& f, const Mat3& elastic_b) {
  const Mat3 fb = f * elastic_b;
  const Vec3 f0 = f.row(0).transpose(), f1 = f.row(1).transpose(), f2 = f.row(2).transpose();
  const Vec3 a0 = fb.row(0).transpose(), a1 = fb.row(1).transpose();
  const Real b00 = a0.dot(f0), b01 = a0.dot(f1), b02 = a0.dot(f2);
  const Real b11 = a1.dot(f1), b12 = a1.dot(f2), b22 = fb.row(2).transpose().dot(f2);
  Mat3 b_trial;
  b_trial << b00, b01, b02,  //
      b01, b11, b12,         //
      b02, b12, b22;
  return b_trial;
}

// Steps 3-4 of Table 3.4 from the decomposition of b^e_tr (step 2).
[[gnu::always_inline]] inline void TrialFromPrincipal(Real K, Real G, const Vec3& b_principal,
                                                      HenckyTrial& t) {
  t.eps = 0.5 * b_principal.array().log();  // (3.34), erratum 2
  t.tau = HenckyStress(K, G, t.eps);
}

}  // namespace

HenckyTrial HenckyTrialState(Real K, Real G, const Mat3& f, const Mat3& elastic_b) {
  HenckyTrial t;
  t.b = TrialB(f, elastic_b);
  Vec3 b_principal;
  SymmetricEigen(t.b, b_principal, t.Q);  // Table 3.4, step 2
  TrialFromPrincipal(K, G, b_principal, t);
  return t;
}

void HenckyTrialStates(Real K, Real G, const Mat3& f0, const Mat3& elastic_b0, const Mat3& f1,
                       const Mat3& elastic_b1, HenckyTrial& t0, HenckyTrial& t1) {
  t0.b = TrialB(f0, elastic_b0);
  t1.b = TrialB(f1, elastic_b1);
  Vec3 b0, b1;
  SymmetricEigen2(t0.b, t1.b, b0, t0.Q, b1, t1.Q);  // Table 3.4, step 2
  TrialFromPrincipal(K, G, b0, t0);
  TrialFromPrincipal(K, G, b1, t1);
}

void HenckyTrialStates4(Real K, Real G, const Mat3* f, const Mat3* elastic_b, HenckyTrial* t) {
  Mat3 b[4], Q[4];
  Vec3 principal[4];
  for (int k = 0; k < 4; ++k) b[k] = t[k].b = TrialB(f[k], elastic_b[k]);
  SymmetricEigen4(b, principal, Q);  // Table 3.4, step 2
  for (int k = 0; k < 4; ++k) {
    t[k].Q = Q[k];
    TrialFromPrincipal(K, G, principal[k], t[k]);
  }
}

Mat3 ExpTwice(const Mat3& eps) {
  Vec3 eps_principal;
  Mat3 Q;
  SymmetricEigen(eps, eps_principal, Q);
  return FromPrincipal(Q, (2.0 * eps_principal).array().exp().matrix());
}

Mat3 ElasticBFromStress(Real K, Real G, const Mat3& tau) {
  // Compliance D^e = 1/(9K) 1 x 1 + 1/(2G) I_dev (3.47).
  const Mat3 eps = tau.trace() / (9.0 * K) * Mat3::Identity() + Dev(tau) / (2.0 * G);
  return ExpTwice(Sym(eps));
}

Real HenckyEnergy(Real K, Real G, Real J, const Mat3& stress) {
  const Mat3 tau = J * stress;  // (3.37)
  const Real tr = tau.trace();
  return tr * tr / (18.0 * K) + Dev(tau).squaredNorm() / (4.0 * G);  // (3.45)
}

Real HenckyEnergy(Real K, Real G, Real J, const SymMat3& stress) {
  const Real* v = stress.v;  // tau = J sigma (3.37), Voigt xx yy zz xy yz xz
  const Real tr = J * (v[0] + v[1] + v[2]), m = tr / 3.0;
  const Real d0 = J * v[0] - m, d1 = J * v[1] - m, d2 = J * v[2] - m;
  const Real dev2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * J * J * (v[3] * v[3] + v[4] * v[4] + v[5] * v[5]);
  return tr * tr / (18.0 * K) + dev2 / (4.0 * G);  // (3.45)
}

}  // namespace surge

// Hencky elasticity and the principal-space return skeleton (Mast 2013 Table 3.4).
#include "materials/hencky.h"

#include <cmath>
#include <cstring>

#include "core/simd.h"
#include "materials/symmetric_eigen.h"

#if SURGE_HAVE_WIDE_SIMD
#include <immintrin.h>  // _mm256_zeroupper (the wide finish)
#endif

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

namespace {

// A group of four particles for HenckyFinish4, lane-major ([component][lane]): its inputs, the
// principal values 2 eps_e (then exp(2 eps_e) in place) and the two tensors' distinct entries in
// the order 00 01 02 11 12 22.
struct FinishGroup {
  alignas(32) Real tau[3][4];
  alignas(32) Real q[9][4];  // Q(r, c) at [3 r + c]
  alignas(32) Real J[4];
  alignas(32) Real x[3][4];
  alignas(32) Real b[6][4];
  alignas(32) Real s[6][4];
};

[[gnu::always_inline]] inline Real4 Load4(const Real* p) {
  Real4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void Store4(Real* p, Real4 v) { std::memcpy(p, &v, sizeof v); }

// eps_e = [D^e_d] tau (HenckyStrain, (3.47)) and x = 2 eps_e, lane-wise in HenckyStrain's order.
[[gnu::always_inline]] inline void StrainLanes(Real K, Real G, FinishGroup& g) {
  const Real4 a0 = Load4(g.tau[0]), a1 = Load4(g.tau[1]), a2 = Load4(g.tau[2]);
  const Real4 tr = (a0 + a1) + a2, vol = tr / (9.0 * K), third = tr / 3.0;
  const Real g2 = 2.0 * G;
  Store4(g.x[0], 2.0 * (vol + (a0 - third) / g2));
  Store4(g.x[1], 2.0 * (vol + (a1 - third) / g2));
  Store4(g.x[2], 2.0 * (vol + (a2 - third) / g2));
}

// Q diag(v) Q^T's distinct entries, lane-wise in FromPrincipal's order.
[[gnu::always_inline]] inline void FromPrincipalLanes(const Real4 (&q)[9], const Real4 (&v)[3],
                                                      Real4 (&m)[6]) {
  Real4 r0[3], r1[3], r2[3];
  for (int k = 0; k < 3; ++k) {
    r0[k] = q[k] * v[k];
    r1[k] = q[3 + k] * v[k];
    r2[k] = q[6 + k] * v[k];
  }
  m[0] = (r0[0] * q[0] + r0[1] * q[1]) + r0[2] * q[2];
  m[1] = (r0[0] * q[3] + r0[1] * q[4]) + r0[2] * q[5];
  m[2] = (r0[0] * q[6] + r0[1] * q[7]) + r0[2] * q[8];
  m[3] = (r1[0] * q[3] + r1[1] * q[4]) + r1[2] * q[5];
  m[4] = (r1[0] * q[6] + r1[1] * q[7]) + r1[2] * q[8];
  m[5] = r2[0] * q[6] + (r2[1] * q[7] + r2[2] * q[8]);  // Eigen's split sum of an expression
}

// b^e = Q diag(x) Q^T and sigma = Q diag(tau) Q^T / J (Table 3.4, 5(c)-(d), (3.37)).
[[gnu::always_inline]] inline void TensorLanes(FinishGroup& g) {
  Real4 q[9], v[3], m[6];
  for (int k = 0; k < 9; ++k) q[k] = Load4(g.q[k]);
  for (int k = 0; k < 3; ++k) v[k] = Load4(g.x[k]);
  FromPrincipalLanes(q, v, m);
  for (int k = 0; k < 6; ++k) Store4(g.b[k], m[k]);
  for (int k = 0; k < 3; ++k) v[k] = Load4(g.tau[k]);
  FromPrincipalLanes(q, v, m);
  const Real4 J = Load4(g.J);
  for (int k = 0; k < 6; ++k) Store4(g.s[k], m[k] / J);
}

void StrainPortable(Real K, Real G, FinishGroup& g) { StrainLanes(K, G, g); }
void TensorPortable(FinishGroup& g) { TensorLanes(g); }

#if SURGE_HAVE_WIDE_SIMD
// The AVX builds; each clears the upper register halves before it returns to SSE code (GCC 12
// does not, see SymmetricEigen4).
SURGE_TARGET_WIDE void StrainWide(Real K, Real G, FinishGroup& g) {
  StrainLanes(K, G, g);
#if !defined(__clang__)
  _mm256_zeroupper();
#endif
}
SURGE_TARGET_WIDE void TensorWide(FinishGroup& g) {
  TensorLanes(g);
#if !defined(__clang__)
  _mm256_zeroupper();
#endif
}
#endif

// The 6 distinct entries (00 01 02 11 12 22) of lane k as a symmetric matrix.
Mat3 SymmetricOf(const Real (&m)[6][4], int k) {
  Mat3 a;
  a << m[0][k], m[1][k], m[2][k],  //
      m[1][k], m[3][k], m[4][k],   //
      m[2][k], m[4][k], m[5][k];
  return a;
}

}  // namespace

void HenckyFinish4(const HenckyTrial* t, Real K, Real G, const Vec3* tau, const Real* J,
                   unsigned lanes, Mat3* elastic_b, Mat3* stress) {
  FinishGroup g;
  bool elastic[4];
  for (int k = 0; k < 4; ++k) {
    const bool on = lanes & (1u << k);
    const Vec3& tk = on ? tau[k] : t[k].tau;  // an unused lane computes on finite values
    elastic[k] = tk == t[k].tau;
    for (int i = 0; i < 3; ++i) g.tau[i][k] = tk(i);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) g.q[3 * r + c][k] = t[k].Q(r, c);
    g.J[k] = on ? J[k] : 1.0;
  }
#if SURGE_HAVE_WIDE_SIMD
  const bool wide = WideSimd();
  wide ? StrainWide(K, G, g) : StrainPortable(K, G, g);
#else
  StrainPortable(K, G, g);
#endif
  for (int k = 0; k < 4; ++k) {  // Table 3.4, 5(c): b^e principal values exp(2 eps_e)
    if (elastic[k]) continue;
    // Through Eigen's array exp, as HenckyFinish: it takes a pair of the three in a packet.
    const Vec3 v = Vec3(g.x[0][k], g.x[1][k], g.x[2][k]).array().exp().matrix();
    for (int i = 0; i < 3; ++i) g.x[i][k] = v(i);
  }
#if SURGE_HAVE_WIDE_SIMD
  wide ? TensorWide(g) : TensorPortable(g);
#else
  TensorPortable(g);
#endif
  for (int k = 0; k < 4; ++k) {
    if (!(lanes & (1u << k))) continue;
    elastic_b[k] = elastic[k] ? t[k].b : SymmetricOf(g.b, k);  // elastic: b^e_tr, as HenckyFinish
    stress[k] = SymmetricOf(g.s, k);
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

// Symmetric 3x3 eigen-decomposition: closed-form extreme root plus an exact 2x2 rotation.
//
// The algorithm is written once over a lane type: `double` for one matrix, and a two-lane vector
// (core/simd.h) for two matrices at a time. Every lane operation is an IEEE operation on that
// lane (+, -, *, /, sqrt, comparisons and selections; no FMA: -ffp-contract=off), and branches are
// selections, so a lane of the pair gives bitwise the result of the one-matrix call. The pair
// exists for speed: the decomposition is a chain of dependent divisions and square roots, and two
// chains in one instruction stream take little longer than one.
#include "materials/symmetric_eigen.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "core/simd.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>  // _mm256_zeroupper (SymmetricEigen4)
#endif

namespace surge {
namespace {

// One matrix: plain doubles, branches as selections.
struct ScalarLane {
  using T = Real;
  using M = bool;
  static T Sqrt(T a) { return std::sqrt(a); }
  static T Abs(T a) { return std::abs(a); }
  static T Sel(M m, T a, T b) { return m ? a : b; }
  static T Splat(Real a) { return a; }
};

// Two matrices: GCC/Clang vector extensions; comparisons give lane masks, `m ? a : b` selects.
struct PairLane {
  using T = Real2;
  typedef int64_t M __attribute__((vector_size(2 * sizeof(int64_t))));
  static T Sqrt(T a) {
#if defined(__SSE2__)
    return T(_mm_sqrt_pd(__m128d(a)));
#else
    return T{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
  }
  static T Abs(T a) { return T(M(a) & M{INT64_MAX, INT64_MAX}); }
  static T Sel(M m, T a, T b) { return m ? a : b; }
  static T Splat(Real a) { return T{a, a}; }
};

#if SURGE_HAVE_WIDE_SIMD
// Four matrices (the AVX build, SymmetricEigen4): as PairLane with four lanes, in generic vector
// operations only (an AVX intrinsic here could not be inlined into the default-target template
// Decompose). Decompose<QuadLane> is inlined into SURGE_TARGET_WIDE Decompose4, where the compiler
// emits AVX instructions for them; sqrt lane by lane (no errno in this file: -fno-math-errno).
struct QuadLane {
  using T = Real4;
  typedef int64_t M __attribute__((vector_size(4 * sizeof(int64_t))));
  [[gnu::always_inline]] static T Sqrt(T a) {
    return T{__builtin_sqrt(a[0]), __builtin_sqrt(a[1]), __builtin_sqrt(a[2]),
             __builtin_sqrt(a[3])};
  }
  [[gnu::always_inline]] static T Abs(T a) {
    return T(M(a) & M{INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX});
  }
  [[gnu::always_inline]] static T Sel(M m, T a, T b) { return m ? a : b; }
  [[gnu::always_inline]] static T Splat(Real a) { return T{a, a, a, a}; }
};
#endif

// The lane helpers of Decompose are always inlined: a Real4 passed to or returned from a call
// between the AVX function and a default-target helper would change the ABI (clang at -O1 kept
// such calls and got wrong lanes).
#define SURGE_LANE_INLINE __attribute__((always_inline))

// The symmetric entries of one or two matrices, and the result before sorting: eigenvalue l[k]
// of the scaled, shifted matrix B = (A - m I) / s with unit eigenvector vec[k] (x, y, z).
template <class L>
struct Lanes {
  using T = typename L::T;
  T a00, a11, a22, a01, a02, a12;  // symmetric part of A
  T m, s;                          // shift and scale
  T l[3];
  T vec[3][3];
};

// Smith (1961) extreme root, its eigenvector by cross products, one Jacobi rotation for the rest
// (see the header). Requires s > 0 in every lane.
template <class L>
[[gnu::always_inline]] inline void Decompose(Lanes<L>& z) {
  using T = typename L::T;
  const T one = L::Splat(1), zero = L::Splat(0);
  // Shift by the mean eigenvalue and scale: B = (A - m I) / s has zero trace and entries <= 1,
  // so its spread is O(1) unless A is a multiple of I (s = 0: handled by the caller).
  const T inv_s = one / z.s;
  const T b00 = (z.a00 - z.m) * inv_s, b11 = (z.a11 - z.m) * inv_s, b22 = (z.a22 - z.m) * inv_s;
  const T b01 = z.a01 * inv_s, b02 = z.a02 * inv_s, b12 = z.a12 * inv_s;

  // Characteristic cubic of the traceless B: l^3 - 3 p l - 2 q = 0, p = tr(B^2)/6, q = det(B)/2;
  // roots 2 sqrt(p) cos(phi + 2 pi k / 3) with phi = acos(q / p^1.5) / 3 (Smith 1961).
  const T p = (b00 * b00 + b11 * b11 + b22 * b22 + L::Splat(2) * (b01 * b01 + b02 * b02 + b12 * b12)) /
              L::Splat(6);
  const T q = L::Splat(0.5) * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) +
                               b02 * (b01 * b12 - b11 * b02));
  // The isolated root (phi = 0 or pi/3 side) is the largest root of l^3 - 3 p l - 2 |q|, signed as
  // q: the largest eigenvalue of B when q >= 0, the smallest otherwise. It lies in
  // [sqrt(3 p), 2 sqrt(p)] and the other two at least sqrt(3 p) away, so it is well separated even
  // at a double root. Scaled, l = sqrt(p) x with x^3 - 3 x - 2 r = 0, r = |q| / p^1.5 in [0, 1]:
  // x(r) = 2 cos(acos(r) / 3) is analytic on [0, 1] (f'(x) = 3 x^2 - 3 >= 6 there), so a quartic
  // (Chebyshev fit, |error| <= 1.9e-5) and two Newton steps (error ~ 0.9 e^2 each: 3e-10, then
  // round-off) give it without acos and cos, and with 2 divisions instead of the 5-6 of a Newton
  // iteration from the upper bound 2. p >= 1/6 here: B has an entry of magnitude 1 and zero trace.
  const T sqrt_p = L::Sqrt(p);
  const T r_raw = L::Abs(q) / (p * sqrt_p);
  const T r = L::Sel(one < r_raw, one, r_raw);  // min(r, 1)
  T x = L::Splat(1.732068948215697) +
        r * (L::Splat(0.3327517502411418) +
             r * (L::Splat(-0.09171204015579826) +
                  r * (L::Splat(0.03500639798623605) - r * L::Splat(0.008128714468727677))));
  for (int it = 0; it < 2; ++it)
    x = x - ((x * x - L::Splat(3)) * x - L::Splat(2) * r) / (L::Splat(3) * (x * x - one));
  const T root = sqrt_p * x;
  const T l1 = L::Sel(q >= zero, root, -root);

  // Its eigenvector: B - l1 I has rank 2, so the largest cross product of two rows spans its kernel.
  const T r0[3] = {b00 - l1, b01, b02}, r1[3] = {b01, b11 - l1, b12}, r2[3] = {b02, b12, b22 - l1};
  const auto cross = [](const T* a, const T* b, T* c) SURGE_LANE_INLINE {
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
  };
  const auto norm2 = [](const T* a) SURGE_LANE_INLINE {
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
  };
  T v[3], c02[3], c12[3];
  cross(r0, r1, v);
  cross(r0, r2, c02);
  cross(r1, r2, c12);
  T vv = norm2(v);
  const T n02 = norm2(c02), n12 = norm2(c12);
  const auto take02 = n02 > vv;
  for (int k = 0; k < 3; ++k) v[k] = L::Sel(take02, c02[k], v[k]);
  vv = L::Sel(take02, n02, vv);
  const auto take12 = n12 > vv;
  for (int k = 0; k < 3; ++k) v[k] = L::Sel(take12, c12[k], v[k]);
  vv = L::Sel(take12, n12, vv);
  const T v_len = L::Sqrt(vv);
  for (T& c : v) c = c / v_len;

  // Orthonormal u, t spanning the complement of v (u drops v's smallest of two components).
  const auto x_big = L::Abs(v[0]) > L::Abs(v[1]);
  const T u_len =
      L::Sqrt(L::Sel(x_big, v[0] * v[0] + v[2] * v[2], v[1] * v[1] + v[2] * v[2]));
  const T u[3] = {L::Sel(x_big, -v[2], zero) / u_len, L::Sel(x_big, zero, v[2]) / u_len,
                  L::Sel(x_big, v[0], -v[1]) / u_len};
  T t[3];
  cross(v, u, t);

  // B restricted to span(u, t) = [[au, e], [e, at]], diagonalised by one Jacobi rotation
  // (Golub & Van Loan Alg. 8.5.1: tan = sgn(theta) / (|theta| + sqrt(1 + theta^2))).
  const auto apply_b = [&](const T* w, T* out) SURGE_LANE_INLINE {
    out[0] = b00 * w[0] + b01 * w[1] + b02 * w[2];
    out[1] = b01 * w[0] + b11 * w[1] + b12 * w[2];
    out[2] = b02 * w[0] + b12 * w[1] + b22 * w[2];
  };
  const auto dot = [](const T* a, const T* b) SURGE_LANE_INLINE {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  T bu[3], bt[3];
  apply_b(u, bu);
  apply_b(t, bt);
  const T au = dot(u, bu), at = dot(t, bt), e = dot(u, bt);
  const auto rotate = e != zero;
  const T e_safe = L::Sel(rotate, e, one);  // lanes without a rotation compute on a dummy
  const T theta = (at - au) / (L::Splat(2) * e_safe);
  const T tn = L::Sel(theta >= zero, one, -one) / (L::Abs(theta) + L::Sqrt(theta * theta + one));
  const T cs = L::Sel(rotate, one / L::Sqrt(tn * tn + one), one);
  const T sn = L::Sel(rotate, tn * cs, zero);
  z.l[0] = l1;
  z.l[1] = L::Sel(rotate, au - tn * e, au);
  z.l[2] = L::Sel(rotate, at + tn * e, at);
  for (int k = 0; k < 3; ++k) {
    z.vec[0][k] = v[k];
    z.vec[1][k] = cs * u[k] - sn * t[k];
    z.vec[2][k] = sn * u[k] + cs * t[k];
  }
}

void Put(Real& slot, int, Real value) { slot = value; }
void Put(Real2& slot, int lane, Real value) { slot[lane] = value; }
#if SURGE_HAVE_WIDE_SIMD
void Put(Real4& slot, int lane, Real value) { slot[lane] = value; }
#endif

// Loads A's symmetric part, its shift m and scale s into lane `lane` (scalar: lane 0 only).
template <class L>
void Load(const Mat3& a, Lanes<L>& z, int lane) {
  const auto put = [lane](typename L::T& slot, Real value) { Put(slot, lane, value); };
  const Real m = (a(0, 0) + a(1, 1) + a(2, 2)) / 3.0;
  const Real b00 = a(0, 0) - m, b11 = a(1, 1) - m, b22 = a(2, 2) - m;
  const Real b01 = 0.5 * (a(0, 1) + a(1, 0)), b02 = 0.5 * (a(0, 2) + a(2, 0));
  const Real b12 = 0.5 * (a(1, 2) + a(2, 1));
  put(z.a00, a(0, 0));
  put(z.a11, a(1, 1));
  put(z.a22, a(2, 2));
  put(z.a01, b01);
  put(z.a02, b02);
  put(z.a12, b12);
  put(z.m, m);
  put(z.s, std::max({std::abs(b00), std::abs(b11), std::abs(b22), std::abs(b01), std::abs(b02),
                     std::abs(b12)}));
}

// Ascending order, as Eigen::SelfAdjointEigenSolver returns them: values m + s l.
void Store(Real m, Real s, const Real l[3], const Real vec[3][3], Vec3& values, Mat3& vectors) {
  int i[3] = {0, 1, 2};
  if (l[i[0]] > l[i[1]]) std::swap(i[0], i[1]);
  if (l[i[1]] > l[i[2]]) std::swap(i[1], i[2]);
  if (l[i[0]] > l[i[1]]) std::swap(i[0], i[1]);
  for (int k = 0; k < 3; ++k) {
    values(k) = m + s * l[i[k]];
    vectors.col(k) = Vec3(vec[i[k]][0], vec[i[k]][1], vec[i[k]][2]);
  }
}

bool IsDiagonal(const Mat3& a) {
  return a(0, 1) == 0 && a(0, 2) == 0 && a(1, 2) == 0 && a(1, 0) == 0 && a(2, 0) == 0 &&
         a(2, 1) == 0;
}

// Already diagonal (uniaxial and isotropic paths, the initial state): exact, and equal diagonal
// entries stay bitwise equal eigenvalues.
void DiagonalEigen(const Mat3& a, Vec3& values, Mat3& vectors) {
  int i[3] = {0, 1, 2};
  if (a(i[0], i[0]) > a(i[1], i[1])) std::swap(i[0], i[1]);
  if (a(i[1], i[1]) > a(i[2], i[2])) std::swap(i[1], i[2]);
  if (a(i[0], i[0]) > a(i[1], i[1])) std::swap(i[0], i[1]);
  vectors.setZero();
  for (int k = 0; k < 3; ++k) {
    values(k) = a(i[k], i[k]);
    vectors(i[k], k) = 1;
  }
}

}  // namespace

void SymmetricEigen(const Mat3& a, Vec3& values, Mat3& vectors) {
  if (IsDiagonal(a)) return DiagonalEigen(a, values, vectors);
  Lanes<ScalarLane> z;
  Load(a, z, 0);
  if (z.s == 0) {  // symmetric part m I (A had only an antisymmetric off-diagonal part)
    values.setConstant(z.m);
    vectors.setIdentity();
    return;
  }
  Decompose(z);
  Store(z.m, z.s, z.l, z.vec, values, vectors);
}

void SymmetricEigen2(const Mat3& a0, const Mat3& a1, Vec3& values0, Mat3& vectors0, Vec3& values1,
                     Mat3& vectors1) {
  Lanes<PairLane> z;
  if (IsDiagonal(a0) || IsDiagonal(a1)) {
    SymmetricEigen(a0, values0, vectors0);
    SymmetricEigen(a1, values1, vectors1);
    return;
  }
  Load(a0, z, 0);
  Load(a1, z, 1);
  if (z.s[0] == 0 || z.s[1] == 0) {
    SymmetricEigen(a0, values0, vectors0);
    SymmetricEigen(a1, values1, vectors1);
    return;
  }
  Decompose(z);
  for (int lane = 0; lane < 2; ++lane) {
    const Real l[3] = {z.l[0][lane], z.l[1][lane], z.l[2][lane]};
    Real vec[3][3];
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) vec[k][c] = z.vec[k][c][lane];
    Store(z.m[lane], z.s[lane], l, vec, lane == 0 ? values0 : values1,
          lane == 0 ? vectors0 : vectors1);
  }
}

#if SURGE_HAVE_WIDE_SIMD
namespace {
// False (nothing written) when a matrix is a multiple of I, as SymmetricEigen handles alone.
SURGE_TARGET_WIDE bool Decompose4(const Mat3* a, Vec3* values, Mat3* vectors) {
  Lanes<QuadLane> z;
  for (int lane = 0; lane < 4; ++lane) {
    Load(a[lane], z, lane);
    if (z.s[lane] == 0) return false;
  }
  Decompose(z);
  Real l[4][3], vec[4][3][3], m[4], scale[4];
  for (int lane = 0; lane < 4; ++lane) {
    for (int k = 0; k < 3; ++k) {
      l[lane][k] = z.l[k][lane];
      for (int c = 0; c < 3; ++c) vec[lane][k][c] = z.vec[k][c][lane];
    }
    m[lane] = z.m[lane];
    scale[lane] = z.s[lane];
  }
  // Clean upper register halves before the SSE code that follows (GCC 12 leaves them dirty here,
  // which slowed every later SSE instruction of the stress update by about half). Clang inserts
  // vzeroupper itself.
#if !defined(__clang__)
  _mm256_zeroupper();
#endif
  for (int lane = 0; lane < 4; ++lane)
    Store(m[lane], scale[lane], l[lane], vec[lane], values[lane], vectors[lane]);
  return true;
}
}  // namespace
#endif

void SymmetricEigen4(const Mat3* a, Vec3* values, Mat3* vectors) {
#if SURGE_HAVE_WIDE_SIMD
  bool plain = WideSimd();
  for (int lane = 0; lane < 4; ++lane) plain = plain && !IsDiagonal(a[lane]);
  if (plain && Decompose4(a, values, vectors)) return;
#endif
  SymmetricEigen2(a[0], a[1], values[0], vectors[0], values[1], vectors[1]);
  SymmetricEigen2(a[2], a[3], values[2], vectors[2], values[3], vectors[3]);
}

}  // namespace surge

// Surge math types: the only place Eigen/Core is named (STYLE H.2).
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // 3x3 determinants
#include <cmath>
#include <cstdint>

namespace surge {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Vec3i = Eigen::Matrix<int, 3, 1>;

inline Mat3 Identity3() { return Mat3::Identity(); }

// The incremental deformation gradient f = I + dt L (Mast 2013 (2.18)), entry by entry: bitwise
// Eigen's `Mat3::Identity() + dt * L`, which GCC called out of line in the hot loops.
inline Mat3 Increment(Real dt, const Mat3& L) {
  Mat3 f;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) f(i, j) = (i == j ? 1.0 : 0.0) + dt * L(i, j);
  return f;
}

// The product a b, entry by entry, bitwise Eigen's `a * b` for 3x3 matrices with SSE2 and no
// FMA (-ffp-contract=off): Eigen forms rows 0 and 1 as two-lane packets summed over k = 0, 1, 2
// from the left, and row 2 as a scalar reduction that pairs k = 1 and 2 first (checked on 1e5
// random pairs). GCC called Eigen's product out of line where the result overwrites an operand
// (`F = f * F` evaluates into a temporary).
[[gnu::always_inline]] inline Mat3 Mul(const Mat3& a, const Mat3& b) {
  Mat3 c;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 2; ++i) c(i, j) = a(i, 0) * b(0, j) + a(i, 1) * b(1, j) + a(i, 2) * b(2, j);
    c(2, j) = a(2, 0) * b(0, j) + (a(2, 1) * b(1, j) + a(2, 2) * b(2, j));
  }
  return c;
}

// det(a), inline: bitwise Eigen's `a.determinant()` for 3x3 (its cofactor expansion along the
// first row, in its order), which GCC called out of line in the particle loops.
[[gnu::always_inline]] inline Real Det3(const Mat3& a) {
  return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
         a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
         a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

// det(a) of a dim-D state: in 2-D (plane strain) of the in-plane block only, in 3-D Det3.
template <int kDim>
[[gnu::always_inline]] inline Real DetOfDim(const Mat3& a) {
  if constexpr (kDim == 2) return a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
  return Det3(a);
}

// Symmetric part of a 3x3 matrix.
inline Mat3 Sym(const Mat3& a) { return 0.5 * (a + a.transpose()); }

// Deviatoric part of a 3x3 matrix.
inline Mat3 Dev(const Mat3& a) { return a - (a.trace() / 3.0) * Mat3::Identity(); }

// A symmetric 3x3 tensor stored as its 6 independent components, Voigt order xx yy zz xy yz xz:
// the particle stress (48 instead of 72 bytes per particle; performance issue). Built from a
// matrix, it keeps the mean of each off-diagonal pair, which is the entry itself, bitwise, for a
// symmetric matrix (a + a is exact and so is the halving).
struct SymMat3 {
  Real v[6] = {0, 0, 0, 0, 0, 0};

  SymMat3() = default;
  template <class Derived>
  SymMat3(const Eigen::MatrixBase<Derived>& m)  // NOLINT(google-explicit-constructor): a value
      : v{m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(0, 1) + m(1, 0)), 0.5 * (m(1, 2) + m(2, 1)),
          0.5 * (m(0, 2) + m(2, 0))} {}

  Mat3 matrix() const {
    Mat3 m;
    m << v[0], v[3], v[5],  //
        v[3], v[1], v[4],   //
        v[5], v[4], v[2];
    return m;
  }
  operator Mat3() const { return matrix(); }  // NOLINT(google-explicit-constructor)
  // Component (i, j), i, j in 0..2.
  Real operator()(int i, int j) const {
    if (i == j) return v[i];
    const int k = i + j;  // 1: xy, 3: yz, 2: xz
    return v[k == 1 ? 3 : k == 3 ? 4 : 5];
  }
  Real trace() const { return v[0] + v[1] + v[2]; }
  bool allFinite() const {
    for (Real x : v)
      if (!std::isfinite(x)) return false;
    return true;
  }
  bool isZero() const {
    for (Real x : v)
      if (x != 0) return false;
    return true;
  }
  bool operator==(const SymMat3& o) const {
    for (int k = 0; k < 6; ++k)
      if (v[k] != o.v[k]) return false;
    return true;
  }
};
static_assert(sizeof(SymMat3) == 6 * sizeof(Real), "SymMat3 must be packed");

}  // namespace surge

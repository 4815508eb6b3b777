// Symmetric 3x3 eigen-decomposition: closed-form extreme root plus an exact 2x2 rotation.
#include "materials/symmetric_eigen.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace surge {

void SymmetricEigen(const Mat3& a, Vec3& values, Mat3& vectors) {
  if (a(0, 1) == 0 && a(0, 2) == 0 && a(1, 2) == 0 && a(1, 0) == 0 && a(2, 0) == 0 && a(2, 1) == 0) {
    // Already diagonal (uniaxial and isotropic paths, the initial state): exact, and equal
    // diagonal entries stay bitwise equal eigenvalues.
    int i[3] = {0, 1, 2};
    if (a(i[0], i[0]) > a(i[1], i[1])) std::swap(i[0], i[1]);
    if (a(i[1], i[1]) > a(i[2], i[2])) std::swap(i[1], i[2]);
    if (a(i[0], i[0]) > a(i[1], i[1])) std::swap(i[0], i[1]);
    vectors.setZero();
    for (int k = 0; k < 3; ++k) {
      values(k) = a(i[k], i[k]);
      vectors(i[k], k) = 1;
    }
    return;
  }
  // Shift by the mean eigenvalue and scale: B = (A - m I) / s has zero trace and entries <= 1,
  // so its spread is O(1) unless A is a multiple of I.
  const Real m = a.trace() / 3.0;
  Real b00 = a(0, 0) - m, b11 = a(1, 1) - m, b22 = a(2, 2) - m;
  Real b01 = 0.5 * (a(0, 1) + a(1, 0)), b02 = 0.5 * (a(0, 2) + a(2, 0));
  Real b12 = 0.5 * (a(1, 2) + a(2, 1));
  const Real s = std::max({std::abs(b00), std::abs(b11), std::abs(b22), std::abs(b01),
                           std::abs(b02), std::abs(b12)});
  if (s == 0) {  // symmetric part m I (A had only an antisymmetric off-diagonal part)
    values.setConstant(m);
    vectors.setIdentity();
    return;
  }
  const Real inv_s = 1.0 / s;
  b00 *= inv_s, b11 *= inv_s, b22 *= inv_s, b01 *= inv_s, b02 *= inv_s, b12 *= inv_s;

  // Characteristic cubic of the traceless B: l^3 - 3 p l - 2 q = 0, p = tr(B^2)/6, q = det(B)/2;
  // roots 2 sqrt(p) cos(phi + 2 pi k / 3) with phi = acos(q / p^1.5) / 3 (Smith 1961).
  const Real p = (b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * (b01 * b01 + b02 * b02 + b12 * b12)) / 6.0;
  const Real q = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) +
                        b02 * (b01 * b12 - b11 * b02));
  // The isolated root (phi = 0 or pi/3 side) is the largest root of l^3 - 3 p l - 2 |q|, signed as
  // q: the largest eigenvalue of B when q >= 0, the smallest otherwise. It lies in
  // [sqrt(3 p), 2 sqrt(p)] and the other two at least sqrt(3 p) away, so it is well separated even
  // at a double root. Scaled, l = sqrt(p) x with x^3 - 3 x - 2 r = 0, r = |q| / p^1.5 in [0, 1]:
  // x(r) = 2 cos(acos(r) / 3) is analytic on [0, 1] (f'(x) = 3 x^2 - 3 >= 6 there), so a quartic
  // (Chebyshev fit, |error| <= 1.9e-5) and two Newton steps (error ~ 0.9 e^2 each: 3e-10, then
  // round-off) give it without acos and cos (12 % of the decomposition's time), and with 2
  // divisions instead of the 5-6 of a Newton iteration from the upper bound 2. p >= 1/6 here:
  // B has an entry of magnitude 1 and zero trace.
  const Real sqrt_p = std::sqrt(p);
  const Real r = std::min(std::abs(q) / (p * sqrt_p), Real(1));
  Real x = 1.732068948215697 +
           r * (0.3327517502411418 +
                r * (-0.09171204015579826 + r * (0.03500639798623605 - r * 0.008128714468727677)));
  for (int it = 0; it < 2; ++it) x -= ((x * x - 3.0) * x - 2.0 * r) / (3.0 * (x * x - 1.0));
  const Real root = sqrt_p * x;
  const Real l1 = q >= 0 ? root : -root;

  // Its eigenvector: B - l1 I has rank 2, so the largest cross product of two rows spans its kernel.
  const Vec3 r0(b00 - l1, b01, b02), r1(b01, b11 - l1, b12), r2(b02, b12, b22 - l1);
  Vec3 v = r0.cross(r1);
  Real vv = v.squaredNorm();
  const Vec3 c02 = r0.cross(r2), c12 = r1.cross(r2);
  if (const Real n = c02.squaredNorm(); n > vv) v = c02, vv = n;
  if (const Real n = c12.squaredNorm(); n > vv) v = c12, vv = n;
  v /= std::sqrt(vv);

  // Orthonormal u, t spanning the complement of v (u drops v's smallest of two components).
  Vec3 u;
  if (std::abs(v.x()) > std::abs(v.y())) {
    u = Vec3(-v.z(), 0, v.x()) / std::sqrt(v.x() * v.x() + v.z() * v.z());
  } else {
    u = Vec3(0, v.z(), -v.y()) / std::sqrt(v.y() * v.y() + v.z() * v.z());
  }
  const Vec3 t = v.cross(u);

  // B restricted to span(u, t) = [[au, e], [e, at]], diagonalised by one Jacobi rotation
  // (Golub & Van Loan Alg. 8.5.1: tan = sgn(theta) / (|theta| + sqrt(1 + theta^2))).
  const Vec3 bu(b00 * u.x() + b01 * u.y() + b02 * u.z(), b01 * u.x() + b11 * u.y() + b12 * u.z(),
                b02 * u.x() + b12 * u.y() + b22 * u.z());
  const Vec3 bt(b00 * t.x() + b01 * t.y() + b02 * t.z(), b01 * t.x() + b11 * t.y() + b12 * t.z(),
                b02 * t.x() + b12 * t.y() + b22 * t.z());
  const Real au = u.dot(bu), at = t.dot(bt), e = u.dot(bt);
  Real cs = 1, sn = 0, l2 = au, l3 = at;
  if (e != 0) {
    const Real theta = (at - au) / (2.0 * e);
    const Real tn = (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
    cs = 1.0 / std::sqrt(tn * tn + 1.0);
    sn = tn * cs;
    l2 = au - tn * e;
    l3 = at + tn * e;
  }
  const Vec3 v2 = cs * u - sn * t, v3 = sn * u + cs * t;

  // Ascending order, as Eigen::SelfAdjointEigenSolver returns them.
  Real l[3] = {l1, l2, l3};
  const Vec3* col[3] = {&v, &v2, &v3};
  int i[3] = {0, 1, 2};
  if (l[i[0]] > l[i[1]]) std::swap(i[0], i[1]);
  if (l[i[1]] > l[i[2]]) std::swap(i[1], i[2]);
  if (l[i[0]] > l[i[1]]) std::swap(i[0], i[1]);
  for (int k = 0; k < 3; ++k) {
    values(k) = m + s * l[i[k]];
    vectors.col(k) = *col[i[k]];
  }
}

}  // namespace surge

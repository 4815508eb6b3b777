// SymmetricEigen (materials/symmetric_eigen.h) against its definition A Q = Q diag(l), Q^T Q = I,
// ascending l, and against Eigen's iterative solver, on the spectra a stress update meets:
// b^e near I, double and triple roots in random frames, and large stretches.
#include "materials/symmetric_eigen.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <functional>
#include <random>

#include "core/simd.h"

namespace surge {
namespace {

struct Worst {
  double residual = 0, orthogonality = 0, eigenvalue = 0, log_tensor = 0;
  bool ascending = true;
  bool pair_equal = true;  // SymmetricEigen2 bitwise equal to SymmetricEigen in both lanes
  bool quad_equal = true;  // SymmetricEigen4 too, in all four lanes (AVX build where WideSimd())
};

// Q diag(ln l) Q^T.
Mat3 FromLog(const Mat3& q, const Vec3& l) { return q * l.array().log().matrix().asDiagonal() * q.transpose(); }

Mat3 RandomRotation(std::mt19937& g) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(g), n(g), n(g), n(g));
  q.normalize();
  return q.toRotationMatrix();
}

// Runs `count` matrices from `make` and records the worst errors relative to |A|.
Worst Check(int count, const std::function<Mat3(std::mt19937&)>& make) {
  std::mt19937 g(20261123);
  Worst w;
  Mat3 previous = Mat3::Identity(), previous_q = Mat3::Identity();
  Vec3 previous_l = Vec3::Ones();
  Mat3 recent[4], recent_q[4];
  Vec3 recent_l[4];
  for (int k = 0; k < count; ++k) {
    const Mat3 a = Sym(make(g));
    Vec3 l;
    Mat3 q;
    SymmetricEigen(a, l, q);
    // The pair form, with the previous matrix in the other lane, is bitwise the one-matrix form.
    Vec3 l0, l1;
    Mat3 q0, q1;
    SymmetricEigen2(a, previous, l0, q0, l1, q1);
    w.pair_equal = w.pair_equal && l0 == l && q0 == q && l1 == previous_l && q1 == previous_q;
    // The quad form, with the three previous matrices in the other lanes.
    recent[k % 4] = a, recent_l[k % 4] = l, recent_q[k % 4] = q;
    if (k >= 3) {
      Vec3 l4[4];
      Mat3 q4[4];
      SymmetricEigen4(recent, l4, q4);
      for (int i = 0; i < 4; ++i)
        w.quad_equal = w.quad_equal && l4[i] == recent_l[i] && q4[i] == recent_q[i];
    }
    previous = a, previous_l = l, previous_q = q;
    const double norm = a.norm();
    w.residual = std::max(w.residual, (a * q - q * l.asDiagonal()).norm() / norm);
    w.orthogonality = std::max(w.orthogonality, (q.transpose() * q - Mat3::Identity()).norm());
    w.ascending = w.ascending && l(0) <= l(1) && l(1) <= l(2);
    // Reference: Eigen's iterative solver in long double.
    using Mat3L = Eigen::Matrix<long double, 3, 3>;
    const Eigen::SelfAdjointEigenSolver<Mat3L> ref(a.cast<long double>());
    const Vec3 ref_l = ref.eigenvalues().cast<double>();
    w.eigenvalue = std::max(w.eigenvalue, (l - ref_l).cwiseAbs().maxCoeff() / norm);
    // The Hencky strain of b = A, the tensor function the stress updates need (3.34): it must
    // not depend on which basis of a repeated eigenspace the solver picks. ln amplifies an
    // absolute eigenvalue error by 1 / l_min, hence the scaling.
    const Mat3 log_a = FromLog(q, l), log_ref = FromLog(ref.eigenvectors().cast<double>(), ref_l);
    w.log_tensor = std::max(w.log_tensor, (log_a - log_ref).norm() * ref_l(0) / norm);
  }
  return w;
}

void ExpectAccurate(const Worst& w) {
  EXPECT_LT(w.residual, 2e-15);
  EXPECT_LT(w.orthogonality, 5e-15);
  EXPECT_LT(w.eigenvalue, 5e-15);
  EXPECT_LT(w.log_tensor, 1e-14);
  EXPECT_TRUE(w.ascending);
  EXPECT_TRUE(w.pair_equal);
  EXPECT_TRUE(w.quad_equal);
}

std::normal_distribution<double> Normal(double sd) { return std::normal_distribution<double>(0, sd); }

TEST(SymmetricEigen, ElasticLeftCauchyGreenNearIdentity) {
  for (double sd : {1e-9, 1e-4, 1e-2, 0.3}) {
    SCOPED_TRACE(sd);
    ExpectAccurate(Check(20000, [sd](std::mt19937& g) {
      auto n = Normal(sd);
      Mat3 f = 0.999 * Mat3::Identity();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) f(i, j) += n(g);
      return Mat3(f * f.transpose());  // b = f f^T
    }));
  }
}

TEST(SymmetricEigen, DoubleRootInRandomFrame) {
  // Axisymmetric states (triaxial test, K0 column): two equal principal stretches.
  ExpectAccurate(Check(20000, [](std::mt19937& g) {
    auto n = Normal(0.05);
    const double radial = 0.9 + n(g), axial = 1.0 + n(g);
    const Mat3 r = RandomRotation(g);
    return Mat3(r * Vec3(radial, axial, radial).asDiagonal() * r.transpose());
  }));
}

TEST(SymmetricEigen, NearDoubleAndTripleRoots) {
  for (double gap : {0.0, 1e-14, 1e-9, 1e-5}) {
    SCOPED_TRACE(gap);
    ExpectAccurate(Check(20000, [gap](std::mt19937& g) {
      auto n = Normal(1.0);
      const Mat3 r = RandomRotation(g);
      const Vec3 l = Vec3::Constant(0.97) + gap * Vec3(n(g), n(g), n(g));
      return Mat3(r * l.asDiagonal() * r.transpose());
    }));
  }
}

TEST(SymmetricEigen, DiagonalAndIsotropicExactly) {
  Vec3 l;
  Mat3 q;
  SymmetricEigen(2.5 * Mat3::Identity(), l, q);
  EXPECT_EQ(l, Vec3::Constant(2.5));
  EXPECT_EQ(q, Mat3::Identity());
  SymmetricEigen(Vec3(3.0, 1.0, 2.0).asDiagonal(), l, q);
  EXPECT_EQ(l, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ((q * l.asDiagonal() * q.transpose() - Mat3(Vec3(3.0, 1.0, 2.0).asDiagonal())).norm(), 0.0);
}

TEST(SymmetricEigen, LargeStretches) {
  // Stretches up to ~10 (the Taylor bar's mushroom): eigenvalues spread over ~2 decades.
  const Worst w = Check(20000, [](std::mt19937& g) {
    auto n = Normal(0.5);
    const Mat3 r = RandomRotation(g);
    const Vec3 stretch(std::exp(n(g)), std::exp(n(g)), std::exp(n(g)));
    return Mat3(r * stretch.cwiseAbs2().asDiagonal() * r.transpose());
  });
  ExpectAccurate(w);
}

TEST(SymmetricEigen, PairEqualsSingleOnSmallIntegerMatrices) {
  // Structured inputs: repeated roots, zero rotations (e = 0) and exactly diagonal lanes.
  std::mt19937 g(7);
  std::uniform_int_distribution<int> n(-2, 2);
  int checked = 0;
  for (int k = 0; k < 20000; ++k) {
    Mat3 a[2];
    for (Mat3& m : a) {
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) m(i, j) = m(j, i) = n(g);
    }
    Vec3 l[2], p[2];
    Mat3 q[2], r[2];
    SymmetricEigen(a[0], l[0], q[0]);
    SymmetricEigen(a[1], l[1], q[1]);
    SymmetricEigen2(a[0], a[1], p[0], r[0], p[1], r[1]);
    for (int i = 0; i < 2; ++i) {
      ASSERT_EQ(p[i], l[i]) << a[i];
      ASSERT_EQ(r[i], q[i]) << a[i];
    }
    ++checked;
  }
  EXPECT_EQ(checked, 20000);
}

// SymmetricEigen4 on the same structured inputs, with the AVX build on (where the CPU has AVX)
// and off: every lane bitwise the one-matrix result, diagonal and isotropic lanes included.
TEST(SymmetricEigen, QuadEqualsSingleOnSmallIntegerMatrices) {
  const bool was = WideSimd();
  for (bool wide : {true, false}) {
    SetWideSimd(wide);
    std::mt19937 g(11);
    std::uniform_int_distribution<int> n(-2, 2);
    for (int k = 0; k < 10000; ++k) {
      Mat3 a[4], q[4], r[4];
      Vec3 l[4], p[4];
      for (Mat3& m : a) {
        for (int i = 0; i < 3; ++i)
          for (int j = i; j < 3; ++j) m(i, j) = m(j, i) = n(g);
      }
      for (int i = 0; i < 4; ++i) SymmetricEigen(a[i], l[i], q[i]);
      SymmetricEigen4(a, p, r);
      for (int i = 0; i < 4; ++i) {
        ASSERT_EQ(p[i], l[i]) << a[i] << (wide ? " (wide)" : "");
        ASSERT_EQ(r[i], q[i]) << a[i] << (wide ? " (wide)" : "");
      }
    }
  }
  SetWideSimd(was);
}

}  // namespace
}  // namespace surge

// core/math.h's hand-written 3x3 helpers (Mul, Det3, Increment) against Eigen's expressions they replace in the stress
// updates: the results must not change when a hot loop switches from one to the other.
#include "core/math.h"

#include <gtest/gtest.h>

#include <random>

namespace surge {
namespace {

// Keeps Eigen's product out of line, as it was in the stress update (F = f F).
[[gnu::noinline]] Mat3 EigenProduct(const Mat3& a, const Mat3& b) { return a * b; }

TEST(MathTest, MulIsEigensProduct) {
  std::mt19937_64 g(20261206);
  std::uniform_real_distribution<double> u(-2, 2);
  double worst = 0;
  int differ = 0;
  for (int t = 0; t < 20000; ++t) {
    Mat3 a, b;
    for (int k = 0; k < 9; ++k) {
      a.data()[k] = u(g);
      b.data()[k] = u(g);
    }
    const Mat3 c = Mul(a, b), e = EigenProduct(a, b);
    differ += c == e ? 0 : 1;
    worst = std::max(worst, (c - e).cwiseAbs().maxCoeff());
  }
  // The summation order (math.h) is Eigen's with SSE2 packets and no FMA, the default build:
  // bitwise equal there. Other instruction sets (SURGE_NATIVE) may order the sums differently.
#if defined(__SSE2__) && !defined(__AVX__) && !defined(__FMA__)
  EXPECT_EQ(differ, 0) << "Mul no longer sums as Eigen's 3x3 product (see core/math.h)";
#endif
  EXPECT_LT(worst, 1e-14);
}

TEST(MathTest, MulOverwritingAnOperandIsTheProduct) {
  Mat3 f, F;
  f << 1.01, 0.02, -0.03, 0.0, 0.99, 0.01, 0.005, -0.02, 1.0;
  F << 1.0, 0.1, 0.0, -0.1, 1.0, 0.2, 0.0, 0.0, 0.9;
  const Mat3 expected = EigenProduct(f, F);
  F = Mul(f, F);  // F_{n+1} = f F_n, as in the stress update
  EXPECT_LT((F - expected).cwiseAbs().maxCoeff(), 1e-15);
}

[[gnu::noinline]] Real EigenDeterminant(const Mat3& a) { return a.determinant(); }

// Det3 replaces Eigen's determinant in the particle loops: bitwise the same, on general matrices
// and on deformation gradients near I.
TEST(MathTest, Det3IsEigensDeterminant) {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1, 1);
  int differ = 0;
  for (int t = 0; t < 20000; ++t) {
    Mat3 a;
    for (int k = 0; k < 9; ++k) a.data()[k] = u(g);
    if (t % 2) a = Mat3::Identity() + 0.01 * a;
    differ += Det3(a) == EigenDeterminant(a) ? 0 : 1;
  }
  EXPECT_EQ(differ, 0);
  Mat3 f;
  f << 2, 0, 0, 0, 3, 0, 0, 0, 0.5;
  EXPECT_EQ(Det3(f), 3.0);
}

TEST(MathTest, IncrementIsIdentityPlusDtL) {
  Mat3 L;
  L << 0.3, -1.2, 0.5, 2.0, -0.7, 0.1, 0.0, 0.4, 1.1;
  const Mat3 f = Increment(1e-3, L), e = Mat3::Identity() + 1e-3 * L;
  EXPECT_EQ(f, e);
}

}  // namespace
}  // namespace surge

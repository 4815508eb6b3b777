// Shape functions: partition of unity, zero-sum gradients, linear reproduction, and gradients
// that match finite differences of the weights, at random points (fixed seed).
#include "transfer/shape_functions.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace surge {
namespace {

constexpr ShapeFunction kAll[] = {ShapeFunction::kLinear, ShapeFunction::kGimp,
                                  ShapeFunction::kQuadraticBspline, ShapeFunction::kCubicBspline};

class ShapeFunctionTest : public ::testing::TestWithParam<std::tuple<ShapeFunction, int>> {};

TEST_P(ShapeFunctionTest, PartitionOfUnityAndZeroSumGradients) {
  const auto [shape, dim] = GetParam();
  const Real dx = 0.37;
  const Real lp = 0.25;  // GIMP half-width (cell units): 2 particles per cell
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<Real> u(-50.0, 50.0);
  Vec3i nodes[64];
  Real w[64];
  Vec3 g[64];
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 x(u(rng), u(rng), dim == 3 ? u(rng) : 0.0);
    const int n = EvaluateShape(shape, dim, x, dx, lp, nodes, w, g);
    Real sum = 0;
    Vec3 gsum = Vec3::Zero();
    Vec3 first_moment = Vec3::Zero();  // sum N_i x_i = x_p (linear reproduction)
    Mat3 grad_moment = Mat3::Zero();   // sum x_i (x) grad N_i = I
    for (int i = 0; i < n; ++i) {
      EXPECT_GE(w[i], -1e-15);
      sum += w[i];
      gsum += g[i];
      const Vec3 xi = nodes[i].cast<Real>() * dx;
      first_moment += w[i] * xi;
      grad_moment += xi * g[i].transpose();
    }
    // Tolerances: a few ulps of the O(1) weights; gradients scale with 1/dx, moments with |x|.
    EXPECT_NEAR(sum, 1.0, 1e-13);
    EXPECT_LT(gsum.norm(), 1e-12 / dx);
    EXPECT_LT((first_moment - x).norm(), 1e-12 * 100);
    Mat3 eye = Mat3::Identity();
    if (dim == 2) eye(2, 2) = 0;
    EXPECT_LT((grad_moment - eye).norm(), 1e-10) << "x = " << x.transpose();
  }
}

TEST_P(ShapeFunctionTest, GradientMatchesFiniteDifference) {
  const auto [shape, dim] = GetParam();
  const Real dx = 0.5, lp = 0.25, h = 1e-6;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<Real> u(-5.0, 5.0);
  Vec3i n0[64], n1[64], n2[64];
  Real w0[64], w1[64], w2[64];
  Vec3 g0[64], g1[64], g2[64];
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 x(u(rng), u(rng), dim == 3 ? u(rng) : 0.0);
    const int n = EvaluateShape(shape, dim, x, dx, lp, n0, w0, g0);
    for (int d = 0; d < dim; ++d) {
      Vec3 e = Vec3::Zero();
      e[d] = h;
      EvaluateShape(shape, dim, x + e, dx, lp, n1, w1, g1);
      EvaluateShape(shape, dim, x - e, dx, lp, n2, w2, g2);
      // Stencils may shift near a node; compare only when both stencils match the centre one.
      if (n1[0] != n0[0] || n2[0] != n0[0]) continue;
      for (int i = 0; i < n; ++i) {
        const Real fd = (w1[i] - w2[i]) / (2 * h);
        EXPECT_NEAR(g0[i][d], fd, 1e-6) << "node " << i << " axis " << d;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllKernels, ShapeFunctionTest,
                         ::testing::Combine(::testing::ValuesIn(kAll), ::testing::Values(2, 3)));

TEST(ShapeFunctionTest, QuadraticBsplineKnownValues) {
  // At a node the quadratic B-spline weights are 1/8, 3/4, 1/8 (Steffen et al. 2008).
  Vec3i nodes[27];
  Real w[27];
  Vec3 g[27];
  const int n = EvaluateShape(ShapeFunction::kQuadraticBspline, 2, Vec3(1.0, 1.0, 0), 1.0, 0,
                              nodes, w, g);
  ASSERT_EQ(n, 9);
  EXPECT_DOUBLE_EQ(w[0], 1.0 / 64);
  EXPECT_DOUBLE_EQ(w[4], 9.0 / 16);
}

}  // namespace
}  // namespace surge

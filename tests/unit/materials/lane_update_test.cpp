// The smooth cap's four-lane update (PlasticUpdate4) against its one-particle form: bitwise equal
// in every lane, with the AVX build and the portable one, over trial states that reach every
// return region.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include "core/simd.h"
#include "materials/hencky.h"
#include "materials/smooth_cap_drucker_prager.h"

namespace surge {
namespace {

bool Same(const Mat3& a, const Mat3& b) {
  return std::memcmp(a.data(), b.data(), sizeof(Mat3)) == 0;
}
bool Same(const History& a, const History& b) {
  return std::memcmp(&a, &b, sizeof(History)) == 0;
}

// A random deformation increment near I and a b^e from a random stress: compressive means from
// 1 kPa to 1 MPa with deviators up to twice the mean, so that the smooth cap's returns reach the
// elastic region, the cone, the cap and the tangent ring.
struct Sample {
  Mat3 f, b;
  Real J;
};

Sample Draw(std::mt19937& g, Real K, Real G) {
  std::uniform_real_distribution<Real> u(-1, 1), e(3, 6);
  const Real p = -std::pow(10.0, e(g));
  Mat3 tau = Mat3::Identity() * p;
  Mat3 dev;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) dev(i, j) = u(g);
  tau += Sym(dev) * std::abs(p) * (1 + u(g));
  if (u(g) > 0.6) tau = Sym(dev) * 20.0;  // near the apex and the cap: tens of Pa
  Mat3 f = Mat3::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f(i, j) += 1e-3 * u(g) * (u(g) > 0 ? 1 : 10);
  return {f, ElasticBFromStress(K, G, tau), 1 + 0.01 * u(g)};
}

TEST(LaneUpdateTest, SmoothCapUpdate4EqualsTheOneParticleUpdateInEveryRegion) {
  const Real K = 8.33e6, G = 3.85e6;
  const Real rho = 2 * std::sin(0.35) / (std::sqrt(3.0) * (3 - std::sin(0.35)));
  const SmoothCapDruckerPragerParams params{K, G, rho, 10.0, 0.05};
  std::mt19937 g(7);
  for (int wide = 0; wide < 2; ++wide) {
    const bool was = SetWideSimd(wide == 1);
    std::array<int, 4> regions{};
    for (int group = 0; group < 2000; ++group) {
      HenckyTrial t[4];
      Mat3 b[4], b1[4], s4[4], s1[4];
      History h[4], h1[4];
      Real J[4];
      for (int k = 0; k < 4; ++k) {
        const Sample s = Draw(g, K, G);
        t[k] = HenckyTrialState(K, G, s.f, s.b);
        b[k] = b1[k] = s.b;
        J[k] = s.J;
        h[k] = h1[k] = History{0.25 * k, -0.5 * k, 1.0};
      }
      // Now and then a non-finite trial stress in one lane: the scalar return takes that lane.
      if (group % 97 == 0) t[group % 4].tau(group % 3) = group % 2 ? NAN : INFINITY;
      PlasticUpdate4(params, t, J, b, h, s4);
      for (int k = 0; k < 4; ++k) {
        PlasticUpdate(params, Mat3::Identity(), t[k], J[k], b1[k], h1[k], s1[k]);
        ASSERT_TRUE(Same(b[k], b1[k]) && Same(s4[k], s1[k]) && Same(h[k], h1[k]))
            << "wide " << wide << " group " << group << " lane " << k << " region "
            << h1[k][kScdpRegion];
        if (std::isfinite(t[k].tau.sum())) regions[size_t(h1[k][kScdpRegion])]++;
      }
    }
    for (int r = 0; r < 4; ++r) EXPECT_GT(regions[size_t(r)], 20) << "region " << r;
    SetWideSimd(was);
  }
}

}  // namespace
}  // namespace surge

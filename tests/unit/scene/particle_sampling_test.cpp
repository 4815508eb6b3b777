// Particle sampling: lattice alignment, region membership, the portable jitter recipe.
#include "scene/particle_sampling.h"

#include <gtest/gtest.h>

#include <random>

namespace surge {
namespace {

TEST(ParticleSamplingTest, BoxLatticeIsHalfOpenAndGridAligned) {
  const BoxRegion box{Vec3(0, 0, 0), Vec3(1, 0.5, 0.25)};
  const std::vector<Vec3> x = SampleRegion(box, 3, 0.125, nullptr);
  EXPECT_EQ(x.size(), 8u * 4u * 2u);
  EXPECT_EQ(x.front(), Vec3(0.0625, 0.0625, 0.0625));
  EXPECT_EQ(x.back(), Vec3(0.9375, 0.4375, 0.1875));
}

TEST(ParticleSamplingTest, TwoDimensionalLatticeLiesInZZero) {
  const BoxRegion box{Vec3(0, 0, 0), Vec3(1, 1, 0)};
  const std::vector<Vec3> x = SampleRegion(box, 2, 0.25, nullptr);
  ASSERT_EQ(x.size(), 16u);
  for (const Vec3& p : x) EXPECT_EQ(p.z(), 0.0);
}

TEST(ParticleSamplingTest, PolygonUsesTheEvenOddRule) {
  PolygonRegion square;  // counter-clockwise unit square
  square.points = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(InsideRegion(square, 2, nullptr, Vec3(0.5, 0.5, 0)));
  EXPECT_FALSE(InsideRegion(square, 2, nullptr, Vec3(1.5, 0.5, 0)));
  square.z0 = 0;
  square.z1 = 1;
  EXPECT_FALSE(InsideRegion(square, 3, nullptr, Vec3(0.5, 0.5, 1.5)));
  EXPECT_TRUE(InsideRegion(square, 3, nullptr, Vec3(0.5, 0.5, 0.5)));
}

TEST(ParticleSamplingTest, CylinderExcludesItsEnds) {
  const CylinderRegion cyl{Vec3(0, 0, 0), Vec3(0, 0, 2), 0.5};
  EXPECT_TRUE(InsideRegion(cyl, 3, nullptr, Vec3(0.3, 0, 1)));
  EXPECT_FALSE(InsideRegion(cyl, 3, nullptr, Vec3(0.4, 0.4, 1)));
  EXPECT_FALSE(InsideRegion(cyl, 3, nullptr, Vec3(0, 0, 2.1)));
  EXPECT_FALSE(InsideRegion(cyl, 3, nullptr, Vec3(0, 0, -0.1)));
}

TEST(ParticleSamplingTest, JitterFollowsThePortableRecipe) {
  std::vector<Vec3> x = {Vec3(1, 2, 3), Vec3(4, 5, 6)};
  JitterPositions(3, 0.1, 0.5, 99, x);
  std::mt19937_64 rng(99);
  const Vec3 base[2] = {Vec3(1, 2, 3), Vec3(4, 5, 6)};
  for (int p = 0; p < 2; ++p) {
    for (int a = 0; a < 3; ++a) {
      const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5;
      EXPECT_EQ(x[p][a], base[p][a] + u * 0.1 * 0.5);
    }
  }
}

TEST(ParticleSamplingTest, JitterLeavesZAloneIn2D) {
  std::vector<Vec3> x(100, Vec3(0.5, 0.5, 0));
  JitterPositions(2, 0.1, 0.9, 3, x);
  for (const Vec3& p : x) {
    EXPECT_EQ(p.z(), 0.0);
    EXPECT_LE(std::abs(p.x() - 0.5), 0.5 * 0.9 * 0.1);
  }
}

TEST(ParticleSamplingTest, CountsCandidatesBeforeSeeding) {
  // 8 points per axis, plus guard indices (an upper bound).
  const Aabb box{Vec3(0, 0, 0), Vec3(1, 1, 1)};
  const double n3 = CountLatticePoints(box, 3, 0.125);
  EXPECT_GE(n3, 8.0 * 8.0 * 8.0);
  EXPECT_LE(n3, 13.0 * 13.0 * 13.0);
  const double n2 = CountLatticePoints(box, 2, 0.125);
  EXPECT_GE(n2, 8.0 * 8.0);
  EXPECT_LE(n2, 13.0 * 13.0);
}

}  // namespace
}  // namespace surge

// The project meshes in assets/ (scripts/make_assets.py): each one reads, builds a
// MeshDistanceField, and classifies a few points whose side is known from its construction.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/mesh_distance.h"
#include "mesh/mesh.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

TriangleMesh Asset(const std::string& name) {
  return ReadTriangleMesh(std::string(SURGE_SOURCE_DIR) + "/assets/" + name);
}

void ExpectBounds(const TriangleMesh& mesh, const Vec3& lo, const Vec3& hi) {
  const Aabb box = BoundingBox(mesh);
  EXPECT_LT((box.min - lo).norm(), 1e-5) << box.min.transpose();  // assimp reads floats
  EXPECT_LT((box.max - hi).norm(), 1e-5) << box.max.transpose();
}

TEST(AssetsTest, BridgePierIsClosedWithTheRoundedNose) {
  const TriangleMesh mesh = Asset("bridge_pier.stl");
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  ExpectBounds(mesh, Vec3(-2, 0, -0.75), Vec3(2, 6, 0.75));
  const MeshDistanceField field(mesh, /*one_sided=*/false);
  EXPECT_NEAR(field.Query(Vec3(0, 3, 0), kInf).distance, -0.75, 1e-6);  // mid-plan, mid-height
  EXPECT_NEAR(field.Query(Vec3(0, 3, 1.25), kInf).distance, 0.5, 1e-6);  // beside a flat side
  // In front of the nose: about 0.5 from the (polygonal) semicircle, normal upstream.
  const MeshDistance nose = field.Query(Vec3(-2.5, 3, 0), kInf);
  EXPECT_NEAR(nose.distance, 0.5, 1e-6);
  EXPECT_GT(nose.normal.dot(-Vec3::UnitX()), 0.99);
  // Inside the rounded corner region of the box [-2, 2] x [-0.75, 0.75], but outside the pier.
  EXPECT_GT(field.Query(Vec3(-1.95, 3, 0.7), kInf).distance, 0);
}

TEST(AssetsTest, MoundIsClosedAndRounded) {
  const TriangleMesh mesh = Asset("mound.obj");
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  ExpectBounds(mesh, Vec3(-3, 0, -3), Vec3(3, 3, 3));
  ASSERT_EQ(mesh.part_names.size(), 1u);
  EXPECT_EQ(mesh.part_names[0], "mound");
  const MeshDistanceField field(mesh, false);
  EXPECT_LT(field.Query(Vec3(0, 1, 0), kInf).distance, -0.5);
  EXPECT_NEAR(field.Query(Vec3(0, 3.5, 0), kInf).distance, 0.5, 1e-6);  // above the apex
  // Near the toe, above the surface y = 3 cos(pi r / 6) and below it.
  EXPECT_GT(field.Query(Vec3(2.5, 3 * std::cos(M_PI * 2.5 / 6) + 0.1, 0), kInf).distance, 0);
  EXPECT_LT(field.Query(Vec3(2.5, 3 * std::cos(M_PI * 2.5 / 6) - 0.1, 0), kInf).distance, 0);
}

TEST(AssetsTest, SquareColumnIsClosedAndSquare) {
  const TriangleMesh mesh = Asset("square_column.obj");
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  ExpectBounds(mesh, Vec3(-0.75, -0.5, -0.75), Vec3(0.75, 8, 0.75));
  const MeshDistanceField field(mesh, false);
  EXPECT_NEAR(field.Query(Vec3(0, 4, 0), kInf).distance, -0.75, 1e-6);  // on the axis
  const MeshDistance front = field.Query(Vec3(-1.25, 4, 0.3), kInf);     // before face x-
  EXPECT_NEAR(front.distance, 0.5, 1e-6);
  EXPECT_GT(front.normal.dot(-Vec3::UnitX()), 0.99);
  EXPECT_NEAR(field.Query(Vec3(1.75, 4, 1.75), kInf).distance, std::sqrt(2.0), 1e-6);  // corner
}

TEST(AssetsTest, ThinPlateIsClosedAndOneCentimetreThick) {
  const TriangleMesh mesh = Asset("thin_plate.obj");
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  ExpectBounds(mesh, Vec3(-0.005, 0, -0.5), Vec3(0.005, 1, 0.5));
  const MeshDistanceField field(mesh, false);
  EXPECT_NEAR(field.Query(Vec3(0, 0.5, 0), kInf).distance, -0.005, 1e-6);  // mid-plane
  const MeshDistance front = field.Query(Vec3(-0.02, 0.5, 0.1), kInf);    // before face x-
  EXPECT_NEAR(front.distance, 0.015, 1e-6);
  EXPECT_GT(front.normal.dot(-Vec3::UnitX()), 0.99);
  EXPECT_NEAR(field.Query(Vec3(0.02, 0.5, -0.1), kInf).distance, 0.015, 1e-6);  // behind it
}

TEST(AssetsTest, VDeflectorIsClosedAndItsOpeningIsOutside) {
  const TriangleMesh mesh = Asset("v_deflector.stl");
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  const MeshDistanceField field(mesh, false);
  const Real s = std::sqrt(0.5);
  // Middle of the +z arm: 2 m along it from the apex, half the 0.5 m thickness in.
  const Vec3 arm = 2.0 * Vec3(s, 0, s) + 0.25 * Vec3(s, 0, -s) + Vec3(0, 1, 0);
  EXPECT_NEAR(field.Query(arm, kInf).distance, -0.25, 1e-6);
  // In the V's opening, on the axis downstream of the inner apex (x = 0.5 / s): outside,
  // nearest to both inner faces at (x - 0.5 / s) s.
  const Vec3 opening(2.0, 1.0, 0.0);
  EXPECT_NEAR(field.Query(opening, kInf).distance, (2.0 - 0.5 / s) * s, 1e-6);
  EXPECT_GT(field.Query(Vec3(-0.5, 1.0, 0.0), kInf).distance, 0);  // upstream of the apex
}

TEST(AssetsTest, TerrainPatchIsOneSided) {
  const TriangleMesh mesh = Asset("terrain_patch.obj");
  EXPECT_GT(CountOpenEdges(mesh), 0);
  ExpectBounds(mesh, Vec3(0, 0, -5), Vec3(20, BoundingBox(mesh).max.y(), 5));
  EXPECT_THROW(MeshDistanceField(mesh, /*one_sided=*/false), std::invalid_argument);
  const MeshDistanceField field(mesh, /*one_sided=*/true);
  // y = 0.05 x + 0.8 exp(-|(x, z) - (12, 1)|^2 / 4.5); far from the bump the surface is planar.
  const Real y = 0.05 * 3 + 0.8 * std::exp(-(81.0 + 9.0) / 4.5);
  EXPECT_NEAR(field.Query(Vec3(3, y + 0.5, -3), kInf).distance, 0.5 / std::sqrt(1.0025), 1e-4);
  EXPECT_LT(field.Query(Vec3(3, y - 0.5, -3), kInf).distance, 0);
  EXPECT_GT(field.Query(Vec3(12, 0.05 * 12 + 0.8 + 0.2, 1), kInf).distance, 0.1);  // over the bump
  EXPECT_LT(field.Query(Vec3(12, 0.05 * 12 + 0.8 - 0.2, 1), kInf).distance, -0.1);
}

// Distance from p to triangle abc by a route independent of the field's (Ericson's region walk):
// the projection onto the plane when it falls inside, else the nearest of the three edges.
Real BruteTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const Vec3 q = p - n.dot(p - a) * n;
  const bool inside = (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 &&
                      (a - c).cross(q - c).dot(n) >= 0;
  if (inside) return std::abs(n.dot(p - a));
  auto segment = [&](const Vec3& u, const Vec3& v) {
    const Real t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
    return (p - u - t * (v - u)).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

// The BVH walk finds the nearest triangle: |distance| equals the minimum over all triangles.
TEST(AssetsTest, BvhSearchMatchesBruteForceOnTheMound) {
  const TriangleMesh mesh = Asset("mound.obj");
  const MeshDistanceField field(mesh, false);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> u(-4, 4);
  std::vector<Vec3> points(2000);
  for (Vec3& p : points) p = Vec3(u(rng), 0.5 * u(rng) + 1.5, u(rng));
  int inside = 0;
  for (const Vec3& p : points) {
    Real brute = kInf;
    for (const auto& t : mesh.triangles) {
      brute = std::min(brute, BruteTriangleDistance(p, mesh.vertices[t[0]], mesh.vertices[t[1]],
                                                    mesh.vertices[t[2]]));
    }
    const MeshDistance d = field.Query(p, kInf);
    ASSERT_NEAR(std::abs(d.distance), brute, 1e-12) << p.transpose();
    ASSERT_EQ(d.distance < 0, InsideMesh(mesh, p)) << p.transpose();
    inside += d.distance < 0;
  }
  EXPECT_GT(inside, 100);
  // Throughput on a mesh of realistic size, and with the pruning radius a contact would use.
  std::vector<Vec3> many(200000);
  for (Vec3& p : many) p = Vec3(u(rng), 0.5 * u(rng) + 1.5, u(rng));
  Real sum = 0;
  for (const Real max_distance : {kInf, 0.2}) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const Vec3& p : many) sum += field.Query(p, max_distance).distance;
    const Real seconds =
        std::chrono::duration<Real>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[ info ] mound (%zu triangles), max_distance %g: %.3g queries/s (1 thread)\n",
                mesh.triangles.size(), max_distance, many.size() / seconds);
  }
  EXPECT_TRUE(std::isfinite(sum));
}

}  // namespace
}  // namespace surge

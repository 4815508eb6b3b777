// MeshDistanceField against closed-form signed distances: the unit cube (box SDF), an extruded
// L (non-convex: the notch is outside), a thin tilted wall (both sides), an open terrain patch
// (one_sided), rejected meshes, and concurrent queries (bitwise equal to serial).
#include "contact/mesh_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "mesh/mesh.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();
constexpr Real kTol = 1e-12;

// Box SDF and its gradient (Quilez's closed form): q = |x - c| - h per axis;
// d = |max(q, 0)| + min(max_i q_i, 0).
struct Sdf {
  Real distance;
  Vec3 normal;
  bool normal_unique;  // false on the medial set (ties between faces inside)
};

Sdf BoxSdf(const Vec3& x, const Vec3& lo, const Vec3& hi) {
  const Vec3 c = 0.5 * (lo + hi);
  const Vec3 h = 0.5 * (hi - lo);
  const Vec3 rel = x - c;
  const Vec3 q = rel.cwiseAbs() - h;
  const Vec3 out = q.cwiseMax(0.0);
  Sdf s;
  if (out.norm() > 0) {
    s.distance = out.norm();
    s.normal = out.cwiseProduct(rel.cwiseSign()) / out.norm();
    s.normal_unique = true;
    return s;
  }
  int axis = 0;
  q.maxCoeff(&axis);
  s.distance = q[axis];
  s.normal = Vec3::Zero();
  s.normal[axis] = rel[axis] >= 0 ? 1 : -1;
  std::array<Real, 3> sorted = {q[0], q[1], q[2]};
  std::sort(sorted.begin(), sorted.end());
  s.normal_unique = sorted[2] - sorted[1] > 1e-9;
  return s;
}

// Prism over the xy polygon `poly` (counter-clockwise, star-shaped from vertex 0) for z in
// [z0, z1]; outward triangles, caps fanned from vertex 0.
TriangleMesh Extrude(const std::vector<std::array<Real, 2>>& poly, Real z0, Real z1) {
  TriangleMesh m;
  const int n = static_cast<int>(poly.size());
  for (const auto& p : poly) m.vertices.emplace_back(p[0], p[1], z0);
  for (const auto& p : poly) m.vertices.emplace_back(p[0], p[1], z1);
  for (int i = 1; i + 1 < n; ++i) {
    m.triangles.push_back({0, i + 1, i});          // bottom, normal -z
    m.triangles.push_back({n, n + i, n + i + 1});  // top, normal +z
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
  }
  return m;
}

TriangleMesh Box(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m = Extrude({{lo.x(), lo.y()}, {hi.x(), lo.y()}, {hi.x(), hi.y()}, {lo.x(), hi.y()}},
                           lo.z(), hi.z());
  return m;
}

// Signed distance to a simple xy polygon (brute force over edges, sign by even-odd crossing),
// and the extrusion's SDF: |(max(d2, 0), max(dz, 0))| + min(max(d2, dz), 0) (exact for prisms).
Real PolygonSdf(const std::vector<std::array<Real, 2>>& poly, Real x, Real y) {
  Real best = kInf;
  bool inside = false;
  const size_t n = poly.size();
  for (size_t i = 0; i < n; ++i) {
    const auto& a = poly[i];
    const auto& b = poly[(i + 1) % n];
    const Real ex = b[0] - a[0], ey = b[1] - a[1];
    const Real t = std::clamp(((x - a[0]) * ex + (y - a[1]) * ey) / (ex * ex + ey * ey), 0.0, 1.0);
    best = std::min(best, std::hypot(x - a[0] - t * ex, y - a[1] - t * ey));
    if ((a[1] > y) != (b[1] > y) && x < a[0] + (y - a[1]) * ex / ey) inside = !inside;
  }
  return inside ? -best : best;
}

Real PrismSdf(const std::vector<std::array<Real, 2>>& poly, Real z0, Real z1, const Vec3& x) {
  const Real d2 = PolygonSdf(poly, x.x(), x.y());
  const Real dz = std::abs(x.z() - 0.5 * (z0 + z1)) - 0.5 * (z1 - z0);
  return std::hypot(std::max(d2, 0.0), std::max(dz, 0.0)) + std::min(std::max(d2, dz), 0.0);
}

Vec3 UnitNormal(const TriangleMesh& m, int t) {
  const auto& tri = m.triangles[t];
  return (m.vertices[tri[1]] - m.vertices[tri[0]])
      .cross(m.vertices[tri[2]] - m.vertices[tri[0]])
      .normalized();
}

TEST(MeshDistanceFieldTest, UnitCubeMatchesBoxSdfEverywhere) {
  const TriangleMesh cube = ReadTriangleMesh(std::string(SURGE_SOURCE_DIR) +
                                             "/tests/data/meshes/unit_cube.stl");
  const MeshDistanceField field(cube, /*one_sided=*/false);
  int checked = 0, inside = 0;
  // Lattice with generic offsets over [-0.6, 1.6]^3: inside, outside, face, edge and corner regions.
  for (int i = 0; i < 23; ++i)
    for (int j = 0; j < 23; ++j)
      for (int k = 0; k < 23; ++k) {
        const Vec3 x(-0.6 + 0.1 * i + 0.0031, -0.6 + 0.1 * j + 0.0047, -0.6 + 0.1 * k + 0.0013);
        const Sdf ref = BoxSdf(x, Vec3::Zero(), Vec3::Ones());
        const MeshDistance d = field.Query(x, kInf);
        ASSERT_NEAR(d.distance, ref.distance, kTol) << x.transpose();
        ASSERT_GE(d.triangle, 0);
        if (ref.normal_unique) {
          ASSERT_LT((d.normal - ref.normal).norm(), kTol) << x.transpose();
        }
        inside += d.distance < 0;
        ++checked;
      }
  EXPECT_EQ(checked, 23 * 23 * 23);
  EXPECT_EQ(inside, 10 * 10 * 10);
}

TEST(MeshDistanceFieldTest, UnitCubeEdgesCornersAndFaces) {
  const TriangleMesh cube = ReadTriangleMesh(std::string(SURGE_SOURCE_DIR) +
                                             "/tests/data/meshes/unit_cube.stl");
  const MeshDistanceField field(cube, false);
  const Vec3 points[] = {
      {1.2, 1.3, 0.5},       // outside, edge region (x+, y+)
      {1.1, -0.2, 1.3},      // outside, corner region
      {-1e-7, 0.4, 0.6},     // just outside face x-
      {1e-7, 0.4, 0.6},      // just inside face x-
      {0.95, 0.97, 0.5},     // inside near an edge: nearest face y+
      {0.999, 0.998, 0.997}, // inside near a corner: nearest face x+
      {0.5 + 1e-9, 1.0 + 1e-9, 0.5},  // just outside the middle of face y+
  };
  for (const Vec3& x : points) {
    const Sdf ref = BoxSdf(x, Vec3::Zero(), Vec3::Ones());
    const MeshDistance d = field.Query(x, kInf);
    EXPECT_NEAR(d.distance, ref.distance, kTol) << x.transpose();
    EXPECT_LT((d.normal - ref.normal).norm(), kTol) << x.transpose();
  }
  // Face-region queries report a triangle of that face (FCL's triangle index is ours).
  const MeshDistance face = field.Query(Vec3(0.3, 0.6, 1.4), kInf);
  EXPECT_LT((UnitNormal(cube, face.triangle) - Vec3::UnitZ()).norm(), 1e-15);
  const MeshDistance below = field.Query(Vec3(0.7, -0.5, 0.2), kInf);
  EXPECT_LT((UnitNormal(cube, below.triangle) + Vec3::UnitY()).norm(), 1e-15);
  // On the surface: distance 0, the pseudo-normal (a corner's is the diagonal).
  const MeshDistance corner = field.Query(Vec3(1, 1, 1), kInf);
  EXPECT_EQ(corner.distance, 0.0);
  EXPECT_LT((corner.normal - Vec3(1, 1, 1).normalized()).norm(), 1e-15);
}

TEST(MeshDistanceFieldTest, MaxDistancePrunesFarPoints) {
  const MeshDistanceField field(Box(Vec3::Zero(), Vec3::Ones()), false);
  const MeshDistance far = field.Query(Vec3(3, 0.5, 0.5), 0.5);
  EXPECT_EQ(far.triangle, -1);
  EXPECT_EQ(far.distance, 0.5);
  const MeshDistance near = field.Query(Vec3(1.25, 0.5, 0.5), 0.5);
  EXPECT_GE(near.triangle, 0);
  EXPECT_NEAR(near.distance, 0.25, kTol);
  const MeshDistance in = field.Query(Vec3(0.8, 0.5, 0.5), 0.5);  // 0.2 inside
  EXPECT_NEAR(in.distance, -0.2, kTol);
}

const std::vector<std::array<Real, 2>> kL = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};

TEST(MeshDistanceFieldTest, NonConvexLMatchesPrismSdfAndNotchIsOutside) {
  const TriangleMesh l = Extrude(kL, 0, 1);
  ASSERT_EQ(CountOpenEdges(l), 0);
  const MeshDistanceField field(l, false);
  int notch = 0;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j)
      for (int k = 0; k < 16; ++k) {
        const Vec3 x(-0.5 + 0.1 * i + 0.0043, -0.5 + 0.1 * j + 0.0029, -0.3 + 0.1 * k + 0.0017);
        const MeshDistance d = field.Query(x, kInf);
        ASSERT_NEAR(d.distance, PrismSdf(kL, 0, 1, x), kTol) << x.transpose();
        if (x.x() > 1 && x.y() > 1 && x.x() < 2 && x.y() < 2 && x.z() > 0 && x.z() < 1) {
          ASSERT_GT(d.distance, 0) << "notch point " << x.transpose();
          ++notch;
        }
      }
  EXPECT_GT(notch, 500);
  // Next to the reflex edge x = y = 1, in the notch: nearest is the face x = 1 (+x outward).
  const MeshDistance d = field.Query(Vec3(1.3, 1.6, 0.5), kInf);
  EXPECT_NEAR(d.distance, 0.3, kTol);
  EXPECT_LT((d.normal - Vec3::UnitX()).norm(), kTol);
  // On the reflex edge's bisector: outside, two faces at 0.01; inside, the edge itself.
  EXPECT_NEAR(field.Query(Vec3(1.01, 1.01, 0.5), kInf).distance, 0.01, kTol);
  EXPECT_NEAR(field.Query(Vec3(0.99, 0.99, 0.5), kInf).distance, -0.01 * std::sqrt(2.0), kTol);
}

TEST(MeshDistanceFieldTest, ThinTiltedWallHasTheRightSignOnBothSides) {
  // Wall 0.01 thick (0.1 of the query spacing 0.1), tilted 30 degrees about z.
  const Real thickness = 0.01, spacing = 0.1;
  const Vec3 lo(-0.5 * thickness, -1, -1), hi(0.5 * thickness, 1, 1);
  TriangleMesh wall = Box(lo, hi);
  const Mat3 r = Eigen::AngleAxis<Real>(M_PI / 6, Vec3::UnitZ()).toRotationMatrix();
  for (Vec3& v : wall.vertices) v = r * v;
  const MeshDistanceField field(wall, false);
  int positive_side = 0, negative_side = 0;
  for (int i = -5; i <= 5; ++i)
    for (int j = -8; j <= 8; ++j)
      for (int k = -8; k <= 8; ++k) {
        const Vec3 local(spacing * i + 0.013, spacing * j + 0.007, spacing * k + 0.011);
        const Vec3 x = r * local;
        const Sdf ref = BoxSdf(local, lo, hi);
        const MeshDistance d = field.Query(x, kInf);
        ASSERT_NEAR(d.distance, ref.distance, kTol) << local.transpose();
        ASSERT_GT(d.distance, 0) << local.transpose();  // no lattice point is inside the wall
        if (ref.normal_unique) {
          ASSERT_LT((d.normal - r * ref.normal).norm(), kTol) << local.transpose();
        }
        if (std::abs(local.y()) < 1 && std::abs(local.z()) < 1) {
          positive_side += local.x() > 0;
          negative_side += local.x() < 0;
          // The normal points from the wall towards the point's own side.
          ASSERT_GT(d.normal.dot(r * Vec3::UnitX()) * local.x(), 0) << local.transpose();
        }
      }
  EXPECT_GT(positive_side, 0);
  EXPECT_GT(negative_side, 0);
  // Inside the wall, off-centre: distance to the nearer face, normal towards it.
  const MeshDistance in = field.Query(r * Vec3(0.003, 0.2, 0.1), kInf);
  EXPECT_NEAR(in.distance, -0.002, kTol);
  EXPECT_LT((in.normal - r * Vec3::UnitX()).norm(), kTol);
}

// Height field y = 0.1 x + 0.05 z over [0, 4] x [0, 2], triangles facing +y.
TriangleMesh Terrain() {
  TriangleMesh m;
  const int nx = 8, nz = 4;
  for (int k = 0; k <= nz; ++k)
    for (int i = 0; i <= nx; ++i) {
      const Real x = 0.5 * i, z = 0.5 * k;
      m.vertices.emplace_back(x, 0.1 * x + 0.05 * z, z);
    }
  auto id = [&](int i, int k) { return k * (nx + 1) + i; };
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i) {
      m.triangles.push_back({id(i, k), id(i, k + 1), id(i + 1, k + 1)});
      m.triangles.push_back({id(i, k), id(i + 1, k + 1), id(i + 1, k)});
    }
  return m;
}

TEST(MeshDistanceFieldTest, OpenMeshNeedsOneSided) {
  const TriangleMesh terrain = Terrain();
  const int open = CountOpenEdges(terrain);
  ASSERT_EQ(open, 2 * 8 + 2 * 4);
  try {
    MeshDistanceField field(terrain, /*one_sided=*/false);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(std::to_string(open) + " edges"), std::string::npos) << what;
    EXPECT_NE(what.find("one_sided: true"), std::string::npos) << what;
  }
}

TEST(MeshDistanceFieldTest, OneSidedTerrainIsSignedAboveAndBelow) {
  const MeshDistanceField field(Terrain(), /*one_sided=*/true);
  const Vec3 up = Vec3(-0.1, 1, -0.05).normalized();
  for (const Real x : {0.3, 1.7, 2.25, 3.6})
    for (const Real z : {0.4, 1.0, 1.55})
      for (const Real h : {-0.3, -0.01, 0.02, 0.25}) {
        const Vec3 p(x, 0.1 * x + 0.05 * z + h, z);
        const MeshDistance d = field.Query(p, kInf);
        EXPECT_NEAR(d.distance, h * up.y(), kTol) << p.transpose();
        EXPECT_LT((d.normal - up).norm(), kTol) << p.transpose();
      }
  // Beyond the patch's edge the nearest feature is the open boundary edge, signed by its face.
  EXPECT_GT(field.Query(Vec3(-0.3, 0.5, 1.0), kInf).distance, 0);
  EXPECT_LT(field.Query(Vec3(-0.3, -0.5, 1.0), kInf).distance, 0);
  EXPECT_GT(field.Query(Vec3(4.5, 1.0, 2.5), kInf).distance, 0);
  EXPECT_LT(field.Query(Vec3(4.5, 0.0, 2.5), kInf).distance, 0);
}

TEST(MeshDistanceFieldTest, RejectsDegenerateTrianglesNamingThem) {
  TriangleMesh m = Box(Vec3::Zero(), Vec3::Ones());
  m.vertices.emplace_back(0.5, 0, 0);  // on the edge 0-1: a zero-area sliver
  m.triangles.push_back({0, 1, static_cast<int>(m.vertices.size()) - 1});
  try {
    MeshDistanceField field(m, /*one_sided=*/true);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 12 is degenerate"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(MeshDistanceField(TriangleMesh{}, true), std::invalid_argument);
}

TEST(MeshDistanceFieldTest, ConcurrentQueriesEqualSerialBitwise) {
  const MeshDistanceField field(Extrude(kL, 0, 1), false);
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<Real> u(-0.5, 2.5);
  std::vector<Vec3> points(200000);
  for (Vec3& p : points) p = Vec3(u(rng), u(rng), u(rng) * 0.5);
  std::vector<MeshDistance> serial(points.size()), parallel(points.size());
  const auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < points.size(); ++i) serial[i] = field.Query(points[i], kInf);
  const auto t1 = std::chrono::steady_clock::now();
  ParallelFor(points.size(), 256, [&](size_t i) { parallel[i] = field.Query(points[i], kInf); });
  const auto t2 = std::chrono::steady_clock::now();
  int inside = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(std::memcmp(&serial[i].distance, &parallel[i].distance, sizeof(Real)), 0) << i;
    ASSERT_EQ(std::memcmp(serial[i].normal.data(), parallel[i].normal.data(), sizeof(Vec3)), 0);
    ASSERT_EQ(serial[i].triangle, parallel[i].triangle);
    inside += serial[i].distance < 0;
  }
  EXPECT_GT(inside, 0);
  const Real serial_s = std::chrono::duration<Real>(t1 - t0).count();
  const Real parallel_s = std::chrono::duration<Real>(t2 - t1).count();
  std::printf("[ info ] L mesh (%zu triangles): %.3g queries/s serial, %.3g queries/s parallel\n",
              field.mesh().triangles.size(), points.size() / serial_s,
              points.size() / parallel_s);
}

}  // namespace
}  // namespace surge

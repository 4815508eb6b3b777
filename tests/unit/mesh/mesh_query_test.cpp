// InsideMesh (ray parity with voting) on a unit cube: interior, exterior, near-face points and
// lattice points whose rays would meet the cube's diagonal edges along axis directions.
#include <gtest/gtest.h>

#include <cmath>

#include "mesh/mesh.h"

namespace surge {
namespace {

TriangleMesh UnitCube() {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return m;
}

TEST(InsideMeshTest, ClassifiesInteriorAndExteriorPoints) {
  const TriangleMesh cube = UnitCube();
  EXPECT_TRUE(InsideMesh(cube, Vec3(0.5, 0.5, 0.5)));
  EXPECT_TRUE(InsideMesh(cube, Vec3(0.1, 0.9, 0.3)));
  EXPECT_FALSE(InsideMesh(cube, Vec3(1.5, 0.5, 0.5)));
  EXPECT_FALSE(InsideMesh(cube, Vec3(-0.5, -0.5, -0.5)));
  EXPECT_FALSE(InsideMesh(cube, Vec3(0.5, 0.5, 3.0)));
}

TEST(InsideMeshTest, ClassifiesPointsNearFaces) {
  const TriangleMesh cube = UnitCube();
  const Real eps = 1e-6;
  for (int axis = 0; axis < 3; ++axis) {
    for (Real face : {0.0, 1.0}) {
      Vec3 in(0.37, 0.61, 0.43), out = in;
      in[axis] = face == 0 ? eps : 1 - eps;
      out[axis] = face == 0 ? -eps : 1 + eps;
      EXPECT_TRUE(InsideMesh(cube, in)) << in.transpose();
      EXPECT_FALSE(InsideMesh(cube, out)) << out.transpose();
    }
  }
}

TEST(InsideMeshTest, CountsEveryLatticePointOfTheCube) {
  // Points (i + 1/2) / 8 on the diagonals y = z etc. would send axis-aligned rays through the
  // faces' diagonal edges; the fixed generic directions must still count all 8^3 inside.
  const TriangleMesh cube = UnitCube();
  int inside = 0;
  for (int k = -2; k < 10; ++k)
    for (int j = -2; j < 10; ++j)
      for (int i = -2; i < 10; ++i) inside += InsideMesh(cube, Vec3(i + 0.5, j + 0.5, k + 0.5) / 8);
  EXPECT_EQ(inside, 512);
}

TEST(InsideMeshTest, WorksForATranslatedScaledMesh) {
  TriangleMesh cube = UnitCube();
  for (Vec3& v : cube.vertices) v = 2.0 * v + Vec3(-1, -1, -1);
  EXPECT_TRUE(InsideMesh(cube, Vec3(0.9, -0.9, 0.0)));
  EXPECT_FALSE(InsideMesh(cube, Vec3(1.1, 0.0, 0.0)));
}

}  // namespace
}  // namespace surge

// ReadTriangleMesh on the unit-cube fixtures (OBJ and ASCII STL) and on bad files.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "mesh/mesh.h"

namespace surge {
namespace {

std::string Data(const std::string& name) {
  return std::string(SURGE_SOURCE_DIR) + "/tests/data/meshes/" + name;
}

void ExpectUnitCube(const TriangleMesh& mesh) {
  EXPECT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.vertices.size(), 8u);  // welded: STL repeats corners per facet
  EXPECT_EQ(CountOpenEdges(mesh), 0);
  const Aabb box = BoundingBox(mesh);
  EXPECT_EQ(box.min, Vec3(0, 0, 0));
  EXPECT_EQ(box.max, Vec3(1, 1, 1));
}

TEST(ReadTriangleMeshTest, ReadsObjCube) { ExpectUnitCube(ReadTriangleMesh(Data("unit_cube.obj"))); }

TEST(ReadTriangleMeshTest, ReadsAsciiStlCube) {
  ExpectUnitCube(ReadTriangleMesh(Data("unit_cube.stl")));
}

TEST(ReadTriangleMeshTest, MissingFileThrowsNamingIt) {
  try {
    ReadTriangleMesh(Data("no_such_file.stl"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_file.stl"), std::string::npos) << e.what();
  }
}

TEST(ReadTriangleMeshTest, GarbageFileThrowsNamingIt) {
  try {
    ReadTriangleMesh(Data("not_a_mesh.obj"));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not_a_mesh.obj"), std::string::npos) << e.what();
  }
}

TEST(ReadTriangleMeshTest, OpenMeshHasOpenEdges) {
  const TriangleMesh mesh = ReadTriangleMesh(Data("open_box.obj"));
  EXPECT_EQ(mesh.triangles.size(), 10u);
  EXPECT_EQ(CountOpenEdges(mesh), 4);  // the rim of the missing face
}

}  // namespace
}  // namespace surge

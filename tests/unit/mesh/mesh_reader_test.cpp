// ReadTriangleMesh on the unit-cube fixtures (OBJ and ASCII STL) and on bad files.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

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

TEST(ReadTriangleMeshTest, ReadsObjCube) {
  const TriangleMesh mesh = ReadTriangleMesh(Data("unit_cube.obj"));
  ExpectUnitCube(mesh);
  ASSERT_EQ(mesh.part_names.size(), 1u);  // no groups: one part
  EXPECT_EQ(mesh.part, std::vector<int>(12, 0));
}

TEST(ReadTriangleMeshTest, ObjGroupsBecomeParts) {
  const TriangleMesh mesh = ReadTriangleMesh(Data("two_parts.obj"));
  ExpectUnitCube(mesh);  // the parts share their rim vertices: still closed
  ASSERT_EQ(mesh.part_names, (std::vector<std::string>{"body", "lid"}));
  ASSERT_EQ(mesh.part.size(), mesh.triangles.size());
  int lid = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    bool on_top = true;
    for (const int v : mesh.triangles[t]) on_top = on_top && mesh.vertices[v].z() == 1.0;
    EXPECT_EQ(mesh.part[t], on_top ? 1 : 0) << "triangle " << t;
    lid += mesh.part[t] == 1;
  }
  EXPECT_EQ(lid, 2);
}

TEST(ReadTriangleMeshTest, ReadsAsciiStlCube) {
  const TriangleMesh mesh = ReadTriangleMesh(Data("unit_cube.stl"));
  ExpectUnitCube(mesh);
  ASSERT_EQ(mesh.part_names.size(), 1u);
  EXPECT_EQ(mesh.part.size(), mesh.triangles.size());
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

// Expects ReadTriangleMesh(path) to throw std::runtime_error whose message names the file and
// contains `part`.
void ExpectRejected(const std::string& path, const std::string& part) {
  try {
    ReadTriangleMesh(path);
    FAIL() << "expected std::runtime_error for " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Found by fuzz_mesh (tests/fuzz/corpus/mesh/regress_*): assimp accepts NaN and overflowing
// coordinates; they broke the weld map's ordering (undefined behaviour) and the inside test.
TEST(ReadTriangleMeshTest, NonFiniteVertexThrowsNamingIt) {
  ExpectRejected(WriteTemp("nan_vertex.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
                 "vertex 1 of mesh");
  ExpectRejected(WriteTemp("inf_vertex.obj", "v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"),
                 "is not finite");
}

// Found by fuzz_mesh (corpus/mesh/regress_ply_triangulate_assert.ply): a PLY face line with no
// indices made assimp's Triangulate step fail an assertion, which aborted the process.
TEST(ReadTriangleMeshTest, FaceWithoutVerticesThrowsNamingIt) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n";
  ExpectRejected(WriteTemp("empty_face.ply", ply), "has no vertices");
}

// Found by fuzz_mesh (corpus/mesh/regress_ply_no_end_header): assimp's PLY reader looped
// forever on a header without end_header.
TEST(ReadTriangleMeshTest, PlyWithoutEndHeaderThrowsNamingIt) {
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n";
  ExpectRejected(WriteTemp("no_end_header.ply", ply), "without an end_header line");
  // ... and on a header line it does not know (corpus/mesh/regress_ply_bad_header_line).
  const std::string bad =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nprmperty float y\n"
      "end_header\n0 0\n";
  ExpectRejected(WriteTemp("bad_header_line.ply", bad), "line 5: unknown PLY header line");
  // ... and on "end_header" followed by a vertical tab instead of the newline (found by the
  // mutation run of fuzz_mesh; corpus/mesh/regress_ply_end_header_vtab).
  const std::string vtab =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nend_header\v0 0 0\n1 0 0\n0 1 0\n";
  ExpectRejected(WriteTemp("vtab.ply", vtab), "line 7: control or non-ASCII character (byte 11)");
}

// A cube as PLY, ASCII and binary: read, and the body checks that keep assimp 5.2 from looping
// (found by fuzz_mesh's mutation runs: a list count of 2^31, an "inf" token) refuse bad bodies
// naming the line or byte.
const char kPlyHeader[] =
    "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 12\nproperty list uchar int vertex_indices\nend_header\n";
const float kCubeVertices[8][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 1, 1},
                                   {1, 0, 0}, {1, 0, 1}, {1, 1, 0}, {1, 1, 1}};
const int kCubeFaces[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                               {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};

std::string AsciiCubePly(const std::string& first_face = "3 0 1 3") {
  std::string s = std::string("ply\nformat ascii 1.0\n") + kPlyHeader;
  for (const auto& v : kCubeVertices)
    s += std::to_string(int(v[0])) + " " + std::to_string(int(v[1])) + " " + std::to_string(int(v[2])) + "\n";
  s += first_face + "\n";
  for (int f = 1; f < 12; ++f)
    s += "3 " + std::to_string(kCubeFaces[f][0]) + " " + std::to_string(kCubeFaces[f][1]) + " " +
         std::to_string(kCubeFaces[f][2]) + "\n";
  return s;
}

std::string BinaryCubePly(uint32_t first_count = 3) {
  std::string s = std::string("ply\nformat binary_little_endian 1.0\n") + kPlyHeader;
  const auto put = [&s](const void* p, size_t n) { s.append(static_cast<const char*>(p), n); };
  for (const auto& v : kCubeVertices) put(v, sizeof v);
  for (int f = 0; f < 12; ++f) {
    const unsigned char n = f == 0 ? static_cast<unsigned char>(first_count) : 3;
    put(&n, 1);
    put(kCubeFaces[f], sizeof kCubeFaces[f]);
  }
  return s;
}

TEST(ReadTriangleMeshTest, PlyAsciiAndBinaryBodiesAreCheckedBeforeAssimpReadsThem) {
  EXPECT_EQ(ReadTriangleMesh(WriteTemp("cube_ascii.ply", AsciiCubePly())).triangles.size(), 12u);
  EXPECT_EQ(ReadTriangleMesh(WriteTemp("cube_binary.ply", BinaryCubePly())).triangles.size(), 12u);
  ExpectRejected(WriteTemp("huge_list.ply", AsciiCubePly("2147483648 0 1 3")),
                 "line 18: list count 2147483648 is not an integer from 0 to 255");
  std::string inf = AsciiCubePly();
  inf.replace(inf.find("end_header\n0 0 0") + 11, 1, "inf");
  ExpectRejected(WriteTemp("inf_token.ply", inf), "line 10: \"inf\" is not a finite number");
  ExpectRejected(WriteTemp("extra_value.ply", AsciiCubePly("3 0 1 3 7")),
                 "line 18: more values than the header declares");
  std::string cut = AsciiCubePly();
  cut.erase(cut.rfind("3 1 7 3\n"));  // the last face line
  ExpectRejected(WriteTemp("cut_ascii.ply", cut), "line 29: the body ends before the 12 instances");
  cut.resize(cut.size() - 3);  // and half of the one before
  ExpectRejected(WriteTemp("cut_ascii2.ply", cut), "line 28: missing list item");
  std::string short_binary = BinaryCubePly();
  short_binary.resize(short_binary.size() - 5);
  ExpectRejected(WriteTemp("cut_binary.ply", short_binary), "the body ends before the 12 instances");
  ExpectRejected(WriteTemp("long_list_binary.ply", BinaryCubePly(200)), "the body ends before");
}

// A named pipe blocked the reader forever (a scene's mesh path is user input).
TEST(ReadTriangleMeshTest, NamedPipeIsNotARegularFile) {
  const std::string path = ::testing::TempDir() + "mesh_fifo_" + std::to_string(getpid()) + ".stl";
  std::remove(path.c_str());
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  ExpectRejected(path, "not a regular file");
  std::remove(path.c_str());
  ExpectRejected("/dev/zero", "not a regular file");
}

TEST(ReadTriangleMeshTest, OpenMeshHasOpenEdges) {
  const TriangleMesh mesh = ReadTriangleMesh(Data("open_box.obj"));
  EXPECT_EQ(mesh.triangles.size(), 10u);
  EXPECT_EQ(CountOpenEdges(mesh), 4);  // the rim of the missing face
}

}  // namespace
}  // namespace surge

// Scene key `obstacles` (issue #5; docs/scene-reference.md "obstacles"): every shape in 2-D and
// 3-D builds the obstacle the run sees (faces, bounds, reference point, motion); malformed
// obstacles give SceneErrors naming file, line and key path; the resolved YAML reads back to
// itself; bodies are carved around obstacles.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "contact/geometry.h"
#include "core/hash.h"
#include "scene/scene.h"

namespace surge {
namespace {

const std::string kMeshDir = std::string(SURGE_SOURCE_DIR) + "/tests/data/meshes/";

// A valid scene without obstacles; line numbers of the appended obstacle text start at 12:
//  1 name            5 domain          9 "- name: block"
//  2 dimension       6 materials:     10 material
//  3 time            7 steel          11 region (body box [0, 1]^dim)
//  4 grid            8 bodies:        12 "obstacles:" (first appended line)
std::string Base(int dim) {
  const bool three = dim == 3;
  return std::string("name: t\n") +
         "dimension: " + std::to_string(dim) + "\n"
         "time: {end: 1.0}\n"
         "grid: {cell_size: 0.25}\n" +
         (three ? "domain: {min: [-1, -1, -1], max: [2, 2, 2]}\n" : "domain: {min: [-1, -1], max: [2, 2]}\n") +
         "materials:\n"
         "  steel: {model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - name: block\n"
         "    material: steel\n" +
         (three ? "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n"
                : "    region: {box: {min: [0, 0], max: [1, 1]}}\n");
}

// Base(dim) with one obstacle whose map body (after "  - ") is `obstacle`: the obstacle's first
// key is on line 13.
std::string WithObstacle(int dim, const std::string& obstacle) {
  return Base(dim) + "obstacles:\n  - " + obstacle;
}

struct Caught {
  bool thrown = false;
  std::string what;
  std::string file;
  int line = 0;
  std::string key_path;
};

Caught Load(const std::string& text) {
  Caught c;
  try {
    LoadSceneFromString(text, "bad.yaml");
  } catch (const SceneError& e) {
    c = {true, e.what(), e.file(), e.line(), e.key_path()};
  }
  return c;
}

// The error names the file and line ("bad.yaml:<line>:"), the key path, and says `fragment`.
void ExpectError(const std::string& text, int line, const std::string& key_path,
                 const std::string& fragment) {
  const Caught c = Load(text);
  ASSERT_TRUE(c.thrown) << "no SceneError for:\n" << text;
  EXPECT_EQ(c.file, "bad.yaml") << c.what;
  EXPECT_EQ(c.line, line) << c.what;
  EXPECT_EQ(c.key_path, key_path) << c.what;
  EXPECT_NE(c.what.find("bad.yaml:" + std::to_string(line) + ":"), std::string::npos) << c.what;
  EXPECT_NE(c.what.find(key_path + ": "), std::string::npos) << c.what;
  EXPECT_NE(c.what.find(fragment), std::string::npos) << c.what;
}

const Obstacle& OnlyObstacle(const LoadedScene& s) {
  EXPECT_EQ(s.model.obstacles.size(), 1u);
  return s.model.obstacles.at(0);
}

// --- good scenes, one per shape ----------------------------------------------------------------

TEST(ObstacleParserTest, Box3DAndDefaults) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: column, shape: {box: {min: [1.25, 0, 0], max: [1.75, 2, 0.5]}}}\n"), "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  EXPECT_EQ(o.name, "column");
  const auto* box = std::get_if<BoxShape>(&o.shape);
  ASSERT_NE(box, nullptr);
  EXPECT_EQ(box->min, Vec3(1.25, 0, 0));
  EXPECT_EQ(box->max, Vec3(1.75, 2, 0.5));
  EXPECT_EQ(o.faces, (std::vector<std::string>{"x-", "x+", "y-", "y+", "z-", "z+"}));
  EXPECT_EQ(o.bounds_min, Vec3(1.25, 0, 0));
  EXPECT_EQ(o.bounds_max, Vec3(1.75, 2, 0.5));
  // Defaults: fixed, frictionless, separable, torque about the centre of the bounds.
  EXPECT_EQ(o.motion.kind, ObstacleMotionKind::kFixed);
  EXPECT_EQ(o.contact.friction, 0.0);
  EXPECT_TRUE(o.contact.separable);
  EXPECT_EQ(o.reference_point, Vec3(1.5, 1, 0.25));
}

TEST(ObstacleParserTest, Box2DHasFourFaces) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(2, "{name: wall, shape: {box: {min: [1.5, -1], max: [2, 1]}}}\n"), "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  ASSERT_TRUE(std::holds_alternative<BoxShape>(o.shape));
  EXPECT_EQ(o.faces, (std::vector<std::string>{"x-", "x+", "y-", "y+"}));
  EXPECT_EQ(o.reference_point, Vec3(1.75, 0, 0));  // z = 0 in 2-D
}

TEST(ObstacleParserTest, SphereAndDisk) {
  for (int dim : {2, 3}) {
    const std::string c = dim == 3 ? "[1.5, 0.5, 0.5]" : "[1.5, 0.5]";
    const LoadedScene s = LoadSceneFromString(
        WithObstacle(dim, "{name: ball, shape: {sphere: {center: " + c + ", radius: 0.25}}}\n"), "s.yaml");
    const Obstacle& o = OnlyObstacle(s);
    const auto* sphere = std::get_if<SphereShape>(&o.shape);
    ASSERT_NE(sphere, nullptr) << dim;
    EXPECT_EQ(sphere->radius, 0.25);
    EXPECT_EQ(o.faces, (std::vector<std::string>{"surface"})) << dim;
    EXPECT_EQ(o.reference_point, dim == 3 ? Vec3(1.5, 0.5, 0.5) : Vec3(1.5, 0.5, 0)) << dim;
  }
}

TEST(ObstacleParserTest, Cylinder3D) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: pile, shape: {cylinder: {base: [1.5, 0, 0.5], top: [1.5, 2, 0.5], radius: 0.2}}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  const auto* cyl = std::get_if<CylinderShape>(&o.shape);
  ASSERT_NE(cyl, nullptr);
  EXPECT_EQ(cyl->top, Vec3(1.5, 2, 0.5));
  EXPECT_EQ(o.faces, (std::vector<std::string>{"side", "base", "top"}));
  // The bounds may be conservative (end disks padded by the radius along the axis too), but
  // they hold the cylinder and are symmetric about its centre, the default reference point.
  EXPECT_NEAR(o.bounds_min.x(), 1.3, 1e-12);
  EXPECT_NEAR(o.bounds_max.x(), 1.7, 1e-12);
  EXPECT_LE(o.bounds_min.y(), 0.0);
  EXPECT_GE(o.bounds_max.y(), 2.0);
  EXPECT_NEAR((o.reference_point - Vec3(1.5, 1, 0.5)).norm(), 0, 1e-12);
}

TEST(ObstacleParserTest, PolygonIn2DAnd3D) {
  const LoadedScene s2 = LoadSceneFromString(
      WithObstacle(2, "{name: wedge, shape: {polygon: {points: [[1.2, 0], [1.9, 0], [1.9, 1]]}}}\n"), "s.yaml");
  EXPECT_EQ(OnlyObstacle(s2).faces, (std::vector<std::string>{"edge0", "edge1", "edge2"}));
  ASSERT_TRUE(std::holds_alternative<PolygonShape>(OnlyObstacle(s2).shape));

  const LoadedScene s3 = LoadSceneFromString(
      WithObstacle(3, "{name: wedge, shape: {polygon: {points: [[1.2, 0], [1.9, 0], [1.9, 1], [1.2, 1]], "
                      "z: [0, 0.5]}}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s3);
  const auto* poly = std::get_if<PolygonShape>(&o.shape);
  ASSERT_NE(poly, nullptr);
  EXPECT_EQ(poly->z0, 0.0);
  EXPECT_EQ(poly->z1, 0.5);
  EXPECT_EQ(o.faces, (std::vector<std::string>{"edge0", "edge1", "edge2", "edge3", "z-", "z+"}));
}

TEST(ObstacleParserTest, PlaneIsNormalisedAndItsPointIsTheReference) {
  for (int dim : {2, 3}) {
    const std::string text =
        dim == 3 ? "{name: slope, shape: {plane: {point: [0, -0.5, 0], normal: [0, 3, 4]}}}\n"
                 : "{name: slope, shape: {plane: {point: [0, -0.5], normal: [0, 2]}}}\n";
    const LoadedScene s = LoadSceneFromString(WithObstacle(dim, text), "s.yaml");
    const Obstacle& o = OnlyObstacle(s);
    const auto* plane = std::get_if<PlaneShape>(&o.shape);
    ASSERT_NE(plane, nullptr);
    const Vec3 expected = dim == 3 ? Vec3(0, 0.6, 0.8) : Vec3(0, 1, 0);
    EXPECT_NEAR((plane->normal - expected).norm(), 0, 1e-15) << dim;
    EXPECT_EQ(o.faces, (std::vector<std::string>{"plane"}));
    EXPECT_EQ(o.reference_point, Vec3(0, -0.5, 0));  // default for planes: the plane's point
    EXPECT_TRUE(std::isinf(o.bounds_min.x()));
  }
}

TEST(ObstacleParserTest, MeshIsTransformedAndNamesItsParts) {
  // Unit cube in two parts (body, lid), scaled by 0.5, turned 90 deg about y, moved to x >= 1.25.
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: crate, shape: {mesh: {file: " + kMeshDir +
                          "two_parts.obj, scale: 0.5, rotate_deg: [0, 90, 0], translate: [1.25, 0, 0.5]}}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  ASSERT_TRUE(std::holds_alternative<MeshShape>(o.shape));
  EXPECT_EQ(o.faces, (std::vector<std::string>{"body", "lid"}));
  // x' = R_y(90) (0.5 x) + t: (x, y, z) -> (z, y, -x) * 0.5 + t, so [0, 1]^3 -> [1.25, 1.75] x
  // [0, 0.5] x [0, 0.5].
  EXPECT_NEAR(o.bounds_min.x(), 1.25, 1e-6);
  EXPECT_NEAR(o.bounds_max.x(), 1.75, 1e-6);
  EXPECT_NEAR(o.bounds_max.y(), 0.5, 1e-6);
  EXPECT_NEAR(o.bounds_min.z(), 0.0, 1e-6);
  EXPECT_NEAR(o.bounds_max.z(), 0.5, 1e-6);
  // The mesh answers like the box it now is: the centre is 0.25 deep.
  const SurfaceQuery q = QueryObstacle(o, PoseAt(o, 0), Vec3(1.5, 0.25, 0.25), 3, 0, 1.0);
  EXPECT_NEAR(q.distance, -0.25, 1e-6);
}

TEST(ObstacleParserTest, OneSidedOpenMeshLoads) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: shell, shape: {mesh: {file: " + kMeshDir +
                          "open_box.obj, translate: [1.25, 0, 0], one_sided: true}}}\n"),
      "s.yaml");
  ASSERT_TRUE(std::holds_alternative<MeshShape>(OnlyObstacle(s).shape));
}

TEST(ObstacleParserTest, PrescribedMotionContactAndReferencePoint) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "name: paddle\n"
                      "    shape: {box: {min: [1.25, 0, 0], max: [1.5, 1, 1]}}\n"
                      "    motion: {prescribed: {velocity: [-1, 0, 0], angular_velocity_deg: [0, 0, 90], "
                      "center: [1.375, 0, 0.5]}}\n"
                      "    contact: {friction: 0.3, separable: false}\n"
                      "    reference_point: [1.25, 0, 0]\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  EXPECT_EQ(o.motion.kind, ObstacleMotionKind::kPrescribed);
  EXPECT_EQ(o.motion.velocity, Vec3(-1, 0, 0));
  EXPECT_NEAR(o.motion.angular_velocity.z(), std::numbers::pi / 2, 1e-15);  // deg/s -> rad/s
  EXPECT_EQ(o.motion.center, Vec3(1.375, 0, 0.5));
  EXPECT_EQ(o.contact.friction, 0.3);
  EXPECT_FALSE(o.contact.separable);
  EXPECT_EQ(o.reference_point, Vec3(1.25, 0, 0));
}

TEST(ObstacleParserTest, RotationCentreDefaultsToTheReferencePointAndIsAScalarIn2D) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(2, "name: rotor\n"
                      "    shape: {box: {min: [1.25, 0], max: [1.75, 0.5]}}\n"
                      "    motion: {prescribed: {angular_velocity_deg: -180}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  EXPECT_EQ(o.motion.velocity, Vec3::Zero());
  EXPECT_NEAR(o.motion.angular_velocity.z(), -std::numbers::pi, 1e-15);
  EXPECT_EQ(o.motion.center, Vec3(1.5, 0.25, 0));
}

TEST(ObstacleParserTest, SeveralObstaclesKeepFileOrder) {
  const LoadedScene s = LoadSceneFromString(
      Base(2) + "obstacles:\n"
                "  - {name: b, shape: {box: {min: [1.5, 0], max: [2, 1]}}}\n"
                "  - {name: a, shape: {plane: {point: [0, -0.5], normal: [0, 1]}}}\n",
      "s.yaml");
  ASSERT_EQ(s.model.obstacles.size(), 2u);
  EXPECT_EQ(s.model.obstacles[0].name, "b");
  EXPECT_EQ(s.model.obstacles[1].name, "a");
}

// --- errors -------------------------------------------------------------------------------------

TEST(ObstacleParserTest, UnknownKeys) {
  ExpectError(WithObstacle(3, "name: c\n"
                              "    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n"
                              "    frcition: 0.3\n"),
              15, "obstacles[0].frcition",
              "unknown key 'frcition' (expected one of: name, shape, motion, contact");
  ExpectError(WithObstacle(3, "name: c\n"
                              "    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n"
                              "    contact: {friction: 0.3, sticky: true}\n"),
              15, "obstacles[0].contact.sticky", "unknown key 'sticky' (expected one of: friction, separable");
  ExpectError(WithObstacle(3, "{name: c, shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1], size: 3}}}\n"), 13,
              "obstacles[0].shape.box.size", "unknown key 'size'");
  ExpectError(WithObstacle(3, "{name: c, shape: {torus: {center: [1.5, 0, 0]}}}\n"), 13,
              "obstacles[0].shape.torus",
              "unknown key 'torus' (expected one of: plane, box, sphere, cylinder, polygon, mesh)");
  ExpectError(WithObstacle(3, "{name: c, shape: {mesh: {file: " + kMeshDir + "unit_cube.stl, scal: 2}}}\n"), 13,
              "obstacles[0].shape.mesh.scal",
              "unknown key 'scal' (expected one of: file, file_hash, scale, rotate_deg, translate, one_sided, faces)");
  ExpectError(Base(3) + "obstacles: {name: c}\n", 12, "obstacles", "expected a list of obstacles");
}

TEST(ObstacleParserTest, MissingNameOrShapeIsReportedAtTheObstacle) {
  ExpectError(WithObstacle(3, "{shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}}\n"), 13,
              "obstacles[0].name", "missing required key 'name'");
  ExpectError(WithObstacle(3, "name: c\n    motion: fixed\n"), 13, "obstacles[0].shape",
              "missing required key 'shape'");
}

TEST(ObstacleParserTest, TwoShapesInOneMap) {
  ExpectError(WithObstacle(3, "name: c\n"
                              "    shape:\n"
                              "      box: {min: [1.5, 0, 0], max: [2, 1, 1]}\n"
                              "      sphere: {center: [1.5, 0, 0], radius: 0.2}\n"),
              15, "obstacles[0].shape",
              "expected exactly one of: plane, box, sphere, cylinder, polygon, mesh, got 2");
}

TEST(ObstacleParserTest, ZeroPlaneNormal) {
  ExpectError(WithObstacle(3, "{name: p, shape: {plane: {point: [0, 0, 0], normal: [0, 0, 0]}}}\n"), 13,
              "obstacles[0].shape.plane.normal", "must not be the zero vector");
  ExpectError(WithObstacle(2, "{name: p, shape: {plane: {point: [0, 0], normal: [0, 0, 1]}}}\n"), 13,
              "obstacles[0].shape.plane.normal", "in 2-D the z component must be 0");
}

TEST(ObstacleParserTest, CylinderAndMeshAre3DOnly) {
  ExpectError(WithObstacle(2, "{name: c, shape: {cylinder: {base: [1.5, 0], top: [1.5, 1], radius: 0.2}}}\n"), 13,
              "obstacles[0].shape.cylinder", "3-D only");
  ExpectError(WithObstacle(2, "{name: m, shape: {mesh: {file: " + kMeshDir + "unit_cube.stl}}}\n"), 13,
              "obstacles[0].shape.mesh", "mesh obstacles are 3-D only (in 2-D use polygon)");
}

TEST(ObstacleParserTest, DuplicateNames) {
  ExpectError(Base(3) + "obstacles:\n"
                        "  - {name: c, shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}}\n"
                        "  - {name: d, shape: {box: {min: [1.5, 1, 0], max: [2, 2, 1]}}}\n"
                        "  - {name: c, shape: {sphere: {center: [-0.5, -0.5, -0.5], radius: 0.2}}}\n",
              15, "obstacles[2].name", "duplicate obstacle name 'c' (also obstacles[0])");
}

TEST(ObstacleParserTest, NameDomainIsReservedAndNamesAreIdentifiers) {
  ExpectError(WithObstacle(3, "{name: domain, shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}}\n"), 13,
              "obstacles[0].name", "'domain' is reserved for the domain walls in the force log");
  ExpectError(WithObstacle(3, "{name: my column, shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}}\n"), 13,
              "obstacles[0].name", "may contain only letters, digits, '_' and '-'");
}

TEST(ObstacleParserTest, BadMotionSpellings) {
  const std::string head = "name: c\n    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n";
  ExpectError(WithObstacle(3, head + "    motion: fix\n"), 15, "obstacles[0].motion",
              "unknown motion 'fix' (expected fixed, {prescribed: {...}} or {dynamic: {...}})");
  ExpectError(WithObstacle(3, head + "    motion: prescribed\n"), 15, "obstacles[0].motion",
              "a prescribed motion needs its velocities");
  ExpectError(WithObstacle(3, head + "    motion: {fixed: true}\n"), 15, "obstacles[0].motion",
              "write motion: fixed (a plain value)");
  ExpectError(WithObstacle(3, head + "    motion: {dynamic: {mass: 10, density: 2000}}\n"), 15,
              "obstacles[0].motion.dynamic", "give exactly one of mass [kg] and density [kg/m^3]");
  ExpectError(WithObstacle(3, head + "    motion: {dynamic: {}}\n"), 15,
              "obstacles[0].motion.dynamic", "give exactly one of mass [kg] and density [kg/m^3]");
  ExpectError(WithObstacle(3, head + "    motion: {dynamic: {mass: 10, restitution: 2}}\n"), 15,
              "obstacles[0].motion.dynamic.restitution", "must be in [0, 1]");
  ExpectError(WithObstacle(3, head + "    motion: {dynamic: {mass: 10, spin: 1}}\n"), 15,
              "obstacles[0].motion.dynamic.spin", "unknown key 'spin'");
  ExpectError(WithObstacle(2, "name: c\n    shape: {box: {min: [1.5, 0], max: [2, 1]}}\n"
                              "    motion: {dynamic: {mass: 10}}\n"),
              15, "obstacles[0].motion.dynamic", "dynamic obstacles are 3-D only");
  ExpectError(WithObstacle(3, "name: c\n    shape: {plane: {point: [0, 0, 0], normal: [0, 1, 0]}}\n"
                              "    motion: {dynamic: {mass: 10}}\n"),
              15, "obstacles[0].motion.dynamic", "a plane is infinite and cannot be dynamic");
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {velocity: [1, 0, 0], spin: 3}}\n"), 15,
              "obstacles[0].motion.prescribed.spin",
              "unknown key 'spin' (expected one of: velocity, angular_velocity_deg, center, table)");
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {velocity: 1}}\n"), 15,
              "obstacles[0].motion.prescribed.velocity", "expected a list of 3 numbers [m/s]");
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {angular_velocity_deg: 90}}\n"), 15,
              "obstacles[0].motion.prescribed.angular_velocity_deg", "expected a list of 3 numbers [deg/s]");
  // 2-D: the rotation is about z, one number.
  ExpectError(WithObstacle(2, "name: c\n    shape: {box: {min: [1.5, 0], max: [2, 1]}}\n"
                              "    motion: {prescribed: {angular_velocity_deg: [0, 0, 90]}}\n"),
              15, "obstacles[0].motion.prescribed.angular_velocity_deg",
              "expected a number [deg/s (about z in 2-D)]");
}

TEST(ObstacleParserTest, NegativeFrictionAndNonBooleanSeparable) {
  const std::string head = "name: c\n    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n";
  ExpectError(WithObstacle(3, head + "    contact: {friction: -0.1}\n"), 15, "obstacles[0].contact.friction",
              "must be >= 0 [-], got -0.1");
  ExpectError(WithObstacle(3, head + "    contact: {separable: maybe}\n"), 15,
              "obstacles[0].contact.separable", "expected true or false, got \"maybe\"");
}

TEST(ObstacleParserTest, FaceConstraintAndGapTest) {
  const std::string head = "name: c\n    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n";
  const Obstacle d = OnlyObstacle(LoadSceneFromString(WithObstacle(3, head), "s.yaml"));
  EXPECT_TRUE(d.contact.interpolated_faces);  // the defaults
  EXPECT_TRUE(d.contact.gap_test);
  const Obstacle o = OnlyObstacle(LoadSceneFromString(
      WithObstacle(3, head + "    contact: {faces: nodes, gap_test: false}\n"), "s.yaml"));
  EXPECT_FALSE(o.contact.interpolated_faces);
  EXPECT_FALSE(o.contact.gap_test);
  ExpectError(WithObstacle(3, head + "    contact: {faces: columns}\n"), 15,
              "obstacles[0].contact.faces", "columns");
  ExpectError(WithObstacle(3, head + "    contact: {faces: nodes, gap_test: 1.5}\n"), 15,
              "obstacles[0].contact.gap_test", "expected true or false");
  ExpectError(WithObstacle(3, head + "    contact: {gap_test: false}\n"), 15,
              "obstacles[0].contact.gap_test", "faces: interpolated needs the gap test");
}

TEST(ObstacleParserTest, MissingMeshFileNamesTheFile) {
  const std::string file = kMeshDir + "no_such_pier.stl";
  const Caught c = Load(WithObstacle(3, "name: pier\n    shape: {mesh: {file: " + file + "}}\n"));
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.file, "bad.yaml") << c.what;
  EXPECT_EQ(c.line, 14) << c.what;
  EXPECT_EQ(c.key_path, "obstacles[0].shape.mesh.file") << c.what;
  EXPECT_NE(c.what.find("no_such_pier.stl"), std::string::npos) << c.what;
}

TEST(ObstacleParserTest, OpenMeshNeedsOneSided) {
  const Caught c = Load(WithObstacle(3, "name: shell\n    shape: {mesh: {file: " + kMeshDir +
                                            "open_box.obj, translate: [1.25, 0, 0]}}\n"));
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.line, 14) << c.what;
  EXPECT_EQ(c.key_path, "obstacles[0].shape.mesh.file") << c.what;
  EXPECT_NE(c.what.find("open_box.obj"), std::string::npos) << c.what;
  EXPECT_NE(c.what.find("the mesh is open"), std::string::npos) << c.what;
  EXPECT_NE(c.what.find("one_sided: true"), std::string::npos) << c.what;
}

TEST(ObstacleParserTest, BodyEntirelyInsideAnObstacle) {
  ExpectError(WithObstacle(3, "{name: c, shape: {box: {min: [-0.5, -0.5, -0.5], max: [1.5, 1.5, 1.5]}}}\n"), 11,
              "bodies[0].region", "every particle of body 'block' lies inside an obstacle");
  ExpectError(WithObstacle(2, "{name: floor, shape: {plane: {point: [0, 1.5], normal: [0, 1]}}}\n"), 11,
              "bodies[0].region", "every particle of body 'block' lies inside an obstacle");
}

// --- resolved YAML ------------------------------------------------------------------------------

// Every field of the obstacles the run sees, compared between two loads.
void ExpectSameObstacles(const LoadedScene& a, const LoadedScene& b) {
  ASSERT_EQ(a.model.obstacles.size(), b.model.obstacles.size());
  for (size_t i = 0; i < a.model.obstacles.size(); ++i) {
    const Obstacle& p = a.model.obstacles[i];
    const Obstacle& q = b.model.obstacles[i];
    EXPECT_EQ(p.name, q.name);
    EXPECT_EQ(p.shape.index(), q.shape.index()) << p.name;
    EXPECT_EQ(p.faces, q.faces) << p.name;
    EXPECT_EQ(p.bounds_min, q.bounds_min) << p.name;
    EXPECT_EQ(p.bounds_max, q.bounds_max) << p.name;
    EXPECT_EQ(p.reference_point, q.reference_point) << p.name;
    EXPECT_EQ(p.motion.kind, q.motion.kind) << p.name;
    EXPECT_EQ(p.motion.velocity, q.motion.velocity) << p.name;
    EXPECT_EQ(p.motion.angular_velocity, q.motion.angular_velocity) << p.name;
    EXPECT_EQ(p.motion.center, q.motion.center) << p.name;
    EXPECT_EQ(p.contact.friction, q.contact.friction) << p.name;
    EXPECT_EQ(p.contact.interpolated_faces, q.contact.interpolated_faces) << p.name;
    EXPECT_EQ(p.contact.gap_test, q.contact.gap_test) << p.name;
    EXPECT_EQ(p.contact.separable, q.contact.separable) << p.name;
    if (const auto* plane = std::get_if<PlaneShape>(&p.shape)) {
      EXPECT_EQ(plane->normal, std::get<PlaneShape>(q.shape).normal) << p.name;
      EXPECT_EQ(plane->point, std::get<PlaneShape>(q.shape).point) << p.name;
    }
  }
}

TEST(ObstacleResolvedYamlTest, EveryKindRereadsToTheSameYaml3D) {
  // Plane normals that are not unit vectors: the resolved YAML must read back to itself, and
  // normalising an already normalised vector can move it by an ulp (it did for [1, 7] in 2-D).
  const std::string text =
      Base(3) +
      "obstacles:\n"
      "  - {name: floor, shape: {plane: {point: [0, -0.75, 0], normal: [1, 7, 3]}}, contact: {friction: 0.6}}\n"
      "  - {name: tilt, shape: {plane: {point: [0, 0, -0.9], normal: [0.1, 0.2, 0.7]}}}\n"
      "  - name: column\n"
      "    shape: {box: {min: [1.25, 0, 0], max: [1.75, 2, 0.5]}}\n"
      "    contact: {friction: 0.25, separable: false}\n"
      "    reference_point: [1.25, 0, 0]\n"
      "  - {name: ball, shape: {sphere: {center: [1.5, 1.5, 1.5], radius: 0.2}}}\n"
      "  - {name: pile, shape: {cylinder: {base: [-0.5, 0, 1.5], top: [-0.5, 1.5, 1.8], radius: 0.1}}}\n"
      "  - {name: wedge, shape: {polygon: {points: [[1.2, 1], [1.9, 1], [1.9, 1.9]], z: [0.1, 0.4]}}}\n"
      "  - name: crate\n"
      "    shape: {mesh: {file: " + kMeshDir + "two_parts.obj, scale: 0.3, rotate_deg: [10, 20, 30], "
      "translate: [-0.6, 1.2, -0.6]}}\n"
      "    motion: {prescribed: {velocity: [0.5, 0, -0.25], angular_velocity_deg: [0, 45, 0]}}\n"
      "  - name: shell\n"
      "    shape: {mesh: {file: " + kMeshDir + "open_box.obj, scale: 0.2, translate: [1.5, -0.8, 1.5], "
      "one_sided: true}}\n"
      "    motion: {prescribed: {velocity: [0, 0.1, 0], angular_velocity_deg: [0, 0, 30], center: [1.6, -0.7, 1.6]}}\n"
      "  - name: boulder\n"
      "    shape: {sphere: {center: [-0.6, 1.6, 1.6], radius: 0.15}}\n"
      "    motion: {dynamic: {density: 2600, velocity: [1, 0, 0], angular_velocity_deg: [0, 0, 10], restitution: 0.2}}\n"
      "    contact: {friction: 0.4, adhesion: 50, faces: nodes, gap_test: false}\n"
      "sensors:\n"
      "  - {name: strip, box: {min: [1.2, 0, 0], max: [1.3, 0.5, 0.5]}}\n";
  const LoadedScene a = LoadSceneFromString(text, "s.yaml");
  ASSERT_EQ(a.model.obstacles.size(), 9u);
  ASSERT_EQ(a.model.sensors.size(), 1u);
  ASSERT_EQ(a.state.rigid.size(), 1u);  // the dynamic boulder
  EXPECT_EQ(a.model.obstacles[8].motion.body, 0);
  EXPECT_EQ(a.state.particles.size(), 512u);  // the obstacles miss the body
  for (const char* key : {"obstacles:", "plane:", "box:", "sphere:", "cylinder:", "polygon:", "mesh:",
                          "one_sided: true", "motion: fixed", "prescribed:", "separable: false",
                          "reference_point:", "dynamic:", "density: 2600", "adhesion: 50", "faces: nodes",
                          "gap_test: false",
                          "sensors:"}) {
    EXPECT_NE(a.resolved_yaml.find(key), std::string::npos) << key << " in\n" << a.resolved_yaml;
  }
  const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
  ExpectSameObstacles(a, b);
  EXPECT_EQ(a.state.particles.x, b.state.particles.x);
}

TEST(ObstacleResolvedYamlTest, EveryKindRereadsToTheSameYaml2D) {
  const std::string text =
      Base(2) +
      "obstacles:\n"
      "  - {name: floor, shape: {plane: {point: [0, -0.75], normal: [1, 7]}}}\n"
      "  - {name: wall, shape: {box: {min: [1.5, 0], max: [2, 1]}}, contact: {friction: 0.1}}\n"
      "  - {name: disk, shape: {sphere: {center: [-0.5, 1.5], radius: 0.3}}, reference_point: [-0.5, 1.2]}\n"
      "  - name: wedge\n"
      "    shape: {polygon: {points: [[1.2, 1.2], [1.9, 1.2], [1.9, 1.9]]}}\n"
      "    motion: {prescribed: {velocity: [-0.5, 0], angular_velocity_deg: 30, center: [1.5, 1.5]}}\n";
  const LoadedScene a = LoadSceneFromString(text, "s.yaml");
  ASSERT_EQ(a.model.obstacles.size(), 4u);
  EXPECT_EQ(a.state.particles.size(), 64u);  // the obstacles miss the body
  const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
  ExpectSameObstacles(a, b);
  EXPECT_EQ(a.state.particles.x, b.state.particles.x);
}

TEST(ObstacleResolvedYamlTest, NoObstaclesKeyWithoutObstacles) {
  const LoadedScene a = LoadSceneFromString(Base(3), "s.yaml");
  EXPECT_EQ(a.resolved_yaml.find("obstacles"), std::string::npos) << a.resolved_yaml;
}

// A mesh file's bytes are hashed into the resolved scene (FNV-1a, core/hash.h), so a restart or a
// sweep notices a changed mesh; a resolved scene pins that content.
TEST(ObstacleResolvedYamlTest, MeshFileContentHashIsResolvedAndPinned) {
  const std::string dir = ::testing::TempDir() + "mesh_hash_test/";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(kMeshDir + "unit_cube.stl", dir + "cube.stl",
                             std::filesystem::copy_options::overwrite_existing);
  const std::string text = WithObstacle(
      3, "{name: m, shape: {mesh: {file: " + dir + "cube.stl, scale: 0.25, translate: [1.25, 0, 0]}}}\n");
  const LoadedScene a = LoadSceneFromString(text, "s.yaml");
  const auto hashes = MeshFileHashes(a.resolved_yaml);
  ASSERT_EQ(hashes.size(), 1u) << a.resolved_yaml;
  EXPECT_EQ(hashes[0].first, dir + "cube.stl");
  std::ifstream in(dir + "cube.stl", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(hashes[0].second, Fnv1aHex(bytes));
  // Re-read as written: the same resolved scene.
  EXPECT_EQ(LoadSceneFromString(a.resolved_yaml, "resolved.yaml").resolved_yaml, a.resolved_yaml);
  // One more byte in the mesh: the resolved scene changes, and the pinned one is refused naming
  // its file_hash key.
  { std::ofstream(dir + "cube.stl", std::ios::app) << "\n"; }
  const LoadedScene b = LoadSceneFromString(text, "s.yaml");
  EXPECT_NE(b.resolved_yaml, a.resolved_yaml);
  EXPECT_NE(MeshFileHashes(b.resolved_yaml).at(0).second, hashes[0].second);
  try {
    LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
    ADD_FAILURE() << "a changed mesh was accepted against its pinned hash";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("resolved.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("obstacles[0].shape.mesh.file_hash"), std::string::npos) << what;
    EXPECT_NE(what.find("the file changed since this scene was resolved"), std::string::npos) << what;
  }
  // A missing file has no hash; the mesh reader's own error names it.
  std::filesystem::remove(dir + "cube.stl");
  EXPECT_THROW(LoadSceneFromString(text, "s.yaml"), SceneError);
}

// --- carving ------------------------------------------------------------------------------------

TEST(ObstacleCarvingTest, BoxBodyOverlappingABoxObstacleKeepsOnlyTheOutside) {
  // Body [0, 1]^3 at spacing 0.125 (dx 0.25, 2 per cell): 8^3 = 512 lattice points (i + 1/2) s.
  // The obstacle [0.5, 1.5]^3 holds the 4^3 = 64 points with every coordinate > 0.5.
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: c, shape: {box: {min: [0.5, 0.5, 0.5], max: [1.5, 1.5, 1.5]}}}\n"), "s.yaml");
  const Particles& P = s.state.particles;
  ASSERT_EQ(P.size(), 512u - 64u);
  for (const Vec3& x : P.x) {
    EXPECT_TRUE(x.x() < 0.5 || x.y() < 0.5 || x.z() < 0.5) << x.transpose();
  }
  // Ids stay the seeding order of the kept particles (no gaps).
  for (size_t p = 0; p < P.size(); ++p) EXPECT_EQ(P.id[p], static_cast<int64_t>(p));
}

TEST(ObstacleCarvingTest, DiskObstacleRemovesTheLatticePointsInsideIt) {
  // 2-D body [0, 1]^2 at spacing 0.125: 64 points; a disk of radius 0.3 about (0.5, 0.5) holds
  // the points with |x - c| < 0.3: offsets (+-1/16, +-3/16) -> 4 at r = 0.088, 8 at r = 0.198,
  // 4 at r = 0.265 = 16 points (the next ring, r = 0.319, is outside).
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(2, "{name: d, shape: {sphere: {center: [0.5, 0.5], radius: 0.3}}}\n"), "s.yaml");
  const Particles& P = s.state.particles;
  EXPECT_EQ(P.size(), 64u - 16u);
  for (const Vec3& x : P.x) EXPECT_GE((x - Vec3(0.5, 0.5, 0)).norm(), 0.3) << x.transpose();
}

TEST(ObstacleCarvingTest, PlaneObstacleCutsTheBodyAtItsSurface) {
  // The half-space below y = 0.5 (normal +y) removes the rows y = 1/16 ... 7/16: 4 of 8 rows.
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(2, "{name: ground, shape: {plane: {point: [0, 0.5], normal: [0, 1]}}}\n"), "s.yaml");
  EXPECT_EQ(s.state.particles.size(), 32u);
  for (const Vec3& x : s.state.particles.x) EXPECT_GT(x.y(), 0.5);
}

// --- shipped scenes -----------------------------------------------------------------------------

// Every scenes/*.yaml loads (parse, build, seed) as shipped and is listed in scenes/README.md.
TEST(ShippedScenesTest, EverySceneLoadsAndIsListed) {
  const std::filesystem::path dir = std::filesystem::path(SURGE_SOURCE_DIR) / "scenes";
  std::ifstream readme_file(dir / "README.md");
  ASSERT_TRUE(readme_file) << "cannot read scenes/README.md";
  const std::string readme((std::istreambuf_iterator<char>(readme_file)), std::istreambuf_iterator<char>());
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    const std::string name = entry.path().filename().string();
    EXPECT_NE(readme.find("(" + name + ")"), std::string::npos) << name << " is not in scenes/README.md";
    try {
      const LoadedScene s = LoadScene(entry.path().string());
      EXPECT_GT(s.state.particles.size(), 0u) << name;
    } catch (const SceneError& e) {
      ADD_FAILURE() << name << ": " << e.what();
    }
  }
  EXPECT_GE(count, 13);  // 10 scenes before issue #5, plus the three obstacle scenes
}

}  // namespace
}  // namespace surge

namespace surge {
namespace {

TEST(ObstacleMotionTableTest, TableIsInterpolatedAndItsSlopeIsTheVelocity) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "name: gate\n"
                      "    shape: {box: {min: [1.25, 0, 0], max: [1.5, 1, 1]}}\n"
                      "    motion: {prescribed: {table: [[0, 0, 0, 0], [0.5, 0.25, 0, 0], [1.5, 0.25, 0.5, 0]]}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  ASSERT_EQ(o.motion.table.size(), 3u);
  const Vec3 c0 = o.motion.center;
  ObstaclePose p = PoseAt(o, 0.25);
  EXPECT_NEAR((p.center - c0 - Vec3(0.125, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((p.velocity - Vec3(0.5, 0, 0)).norm(), 0, 1e-15);
  p = PoseAt(o, 1.0);
  EXPECT_NEAR((p.center - c0 - Vec3(0.25, 0.25, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((p.velocity - Vec3(0, 0.5, 0)).norm(), 0, 1e-15);
  p = PoseAt(o, 3.0);  // held after the table
  EXPECT_NEAR((p.center - c0 - Vec3(0.25, 0.5, 0)).norm(), 0, 1e-15);
  EXPECT_EQ(p.velocity, Vec3::Zero());
  // The resolved YAML keeps the table and reads back to itself.
  EXPECT_NE(s.resolved_yaml.find("table:"), std::string::npos) << s.resolved_yaml;
  const LoadedScene again = LoadSceneFromString(s.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(again.resolved_yaml, s.resolved_yaml);
}

TEST(ObstacleMotionTableTest, BadTables) {
  const std::string head = "name: c\n    shape: {box: {min: [1.5, 0, 0], max: [2, 1, 1]}}\n";
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {table: [[0, 0, 0, 0], [0, 1, 0, 0]]}}\n"),
              15, "obstacles[0].motion.prescribed.table[1][0]", "times must increase");
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {table: [[0, 0, 0]]}}\n"), 15,
              "obstacles[0].motion.prescribed.table[0]", "expected a row [t, dx, dy, dz]");
  ExpectError(WithObstacle(3, head + "    motion: {prescribed: {table: [[0, 0, 0, 0]], velocity: [1, 0, 0]}}\n"),
              15, "obstacles[0].motion.prescribed.table", "either a table or velocity");
}

TEST(ObstacleMeshFacesTest, FacesByNormalGroupTrianglesByDirection) {
  const LoadedScene s = LoadSceneFromString(
      WithObstacle(3, "{name: crate, shape: {mesh: {file: " + kMeshDir +
                          "unit_cube.stl, scale: 0.25, translate: [1.25, 0, 0], faces: normal}}}\n"),
      "s.yaml");
  const Obstacle& o = OnlyObstacle(s);
  EXPECT_EQ(o.faces, (std::vector<std::string>{"x-", "x+", "y-", "y+", "z-", "z+"}));
  // A point just outside the +x side of the cube touches face x+.
  const Vec3 lo = o.bounds_min, hi = o.bounds_max;
  const Vec3 mid = 0.5 * (lo + hi);
  const SurfaceQuery q = QueryObstacle(o, PoseAt(o, 0), Vec3(hi.x() - 1e-3, mid.y(), mid.z()), 3, 0, 1.0);
  ASSERT_EQ(q.count, 1);
  EXPECT_EQ(o.faces[size_t(q.face[0])], "x+");
  EXPECT_NE(s.resolved_yaml.find("faces: normal"), std::string::npos);
}

// Buried faces (on or beyond the domain boundary, Obstacle::buried_faces) never act; a point
// inside leaves through its nearest exposed face (SurfaceQuery::exit_*), by that face's distance:
// the particle projection moves it so (ProjectParticlesOutOfObstacles).
TEST(ObstacleBuriedFacesTest, InsidePointLeavesThroughItsNearestExposedFace) {
  // The domain is [-1, 2]^2. A block on the floor, y- buried: 0.05 above the floor, the nearest
  // exposed face is x- at 0.7 (the projection had moved it by the floor's 0.05 along -x, leaving
  // it inside).
  {
    const LoadedScene s = LoadSceneFromString(
        WithObstacle(2, "{name: foot, shape: {box: {min: [0.2, -1], max: [1.8, 0.2]}}}\n"), "s.yaml");
    const Obstacle& o = OnlyObstacle(s);
    const SurfaceQuery q = QueryObstacle(o, PoseAt(o, 0), Vec3(0.9, -0.95, 0), 2, 0, 0.25);
    EXPECT_EQ(q.exit_face, 0);  // x-
    EXPECT_NEAR(q.exit_distance, -0.7, 1e-12);
    EXPECT_EQ(q.exit_normal, Vec3(-1, 0, 0));
  }
  // A slab across the whole domain: x-, x+ and y- buried, the top the only exposed face. Below
  // the middle the nearer y face is the buried floor; the top, 1.1 up, is the one to move to
  // (the projection had found no face and left the particle inside).
  {
    const LoadedScene s = LoadSceneFromString(
        WithObstacle(2, "{name: slab, shape: {box: {min: [-2, -1], max: [3, 0.2]}}}\n"), "s.yaml");
    const Obstacle& o = OnlyObstacle(s);
    const SurfaceQuery q = QueryObstacle(o, PoseAt(o, 0), Vec3(0.5, -0.9, 0), 2, 0, 0.25);
    EXPECT_EQ(q.exit_face, 3);  // y+
    EXPECT_NEAR(q.exit_distance, -1.1, 1e-12);
    EXPECT_EQ(q.exit_normal, Vec3(0, 1, 0));
  }
  // A 3-D post standing on the floor (a cylinder, base buried): 0.02 above the floor the side,
  // 0.1 away, is the nearest exposed face.
  {
    const LoadedScene s = LoadSceneFromString(
        WithObstacle(3, "{name: post, shape: {cylinder: {base: [1.5, -1, 1.5], top: [1.5, 1, 1.5], "
                        "radius: 0.3}}}\n"),
        "s.yaml");
    const Obstacle& o = OnlyObstacle(s);
    const SurfaceQuery q = QueryObstacle(o, PoseAt(o, 0), Vec3(1.7, -0.98, 1.5), 3, 0, 0.25);
    EXPECT_EQ(q.exit_face, 0);  // the side
    EXPECT_NEAR(q.exit_distance, -0.1, 1e-12);
  }
}

}  // namespace
}  // namespace surge

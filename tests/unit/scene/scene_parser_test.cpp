// Scene parser: every malformed scene gives a SceneError naming the key path and the line;
// --set overrides; resolved YAML reads back to the same model.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace surge {
namespace {

// A valid 3-D scene; tests edit single lines so the line numbers below stay valid.
//  1 name            5 domain          9 "- name: block"
//  2 dimension       6 materials:     10 material
//  3 time            7 steel          11 region
//  4 grid            8 bodies:        12 (first appended line)
const std::string kBase3 =
    "name: t\n"
    "dimension: 3\n"
    "time: {end: 1.0}\n"
    "grid: {cell_size: 0.25}\n"
    "domain: {min: [-1, -1, -1], max: [2, 2, 2]}\n"
    "materials:\n"
    "  steel: {model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - name: block\n"
    "    material: steel\n"
    "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n";

const std::string kBase2 =
    "name: t2\n"
    "dimension: 2\n"
    "time: {end: 1.0}\n"
    "grid: {cell_size: 0.25}\n"
    "domain: {min: [-1, -1], max: [2, 2]}\n"
    "materials:\n"
    "  steel: {model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3}\n"
    "bodies:\n"
    "  - name: block\n"
    "    material: steel\n"
    "    region: {box: {min: [0, 0], max: [1, 1]}}\n";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "fixture text not found: " << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

struct Caught {
  bool thrown = false;
  std::string what;
  std::string file;
  int line = 0;
  std::string key_path;
};

Caught Load(const std::string& text, const std::vector<std::string>& overrides = {}) {
  Caught c;
  try {
    LoadSceneFromString(text, "bad.yaml", overrides);
  } catch (const SceneError& e) {
    c = {true, e.what(), e.file(), e.line(), e.key_path()};
  }
  return c;
}

// The error names the key path and the line ("bad.yaml:<line>:"), and says `fragment`.
void ExpectError(const std::string& text, int line, const std::string& key_path,
                 const std::string& fragment) {
  const Caught c = Load(text);
  ASSERT_TRUE(c.thrown) << "no SceneError for:\n" << text;
  EXPECT_EQ(c.line, line) << c.what;
  EXPECT_EQ(c.key_path, key_path) << c.what;
  EXPECT_NE(c.what.find("bad.yaml:" + std::to_string(line) + ":"), std::string::npos) << c.what;
  EXPECT_NE(c.what.find(key_path + ": "), std::string::npos) << c.what;
  EXPECT_NE(c.what.find(fragment), std::string::npos) << c.what;
}

TEST(SceneParserTest, BaseScenesAreValid) {
  EXPECT_FALSE(Load(kBase3).thrown) << Load(kBase3).what;
  EXPECT_FALSE(Load(kBase2).thrown) << Load(kBase2).what;
}

TEST(SceneParserTest, UnknownTopLevelKey) {
  ExpectError(kBase3 + "gravty: [0, -9.81, 0]\n", 12, "gravty",
              "unknown key 'gravty' (expected one of: name, dimension, time, gravity");
}

TEST(SceneParserTest, UnknownNestedKey) {
  ExpectError(kBase3 + "    veloctiy: [1, 0, 0]\n", 12, "bodies[0].veloctiy",
              "unknown key 'veloctiy' (expected one of: name, material, region,");
}

TEST(SceneParserTest, MissingRequiredKeyReportsTheParentMap) {
  ExpectError(Replace(kBase3, "    material: steel\n", ""), 9, "bodies[0].material",
              "missing required key 'material'");
  ExpectError(Replace(kBase3, "time: {end: 1.0}", "time: {cfl: 0.5}"), 3, "time.end",
              "missing required key 'end'");
}

TEST(SceneParserTest, StringWhereNumberExpected) {
  ExpectError(Replace(kBase3, "cell_size: 0.25", "cell_size: big"), 4, "grid.cell_size",
              "expected a number [m], got \"big\"");
}

TEST(SceneParserTest, StringWhereVectorExpected) {
  const Caught c = Load(kBase3 + "    velocity: fast\n");
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.what,
            "bad.yaml:12:15: bodies[0].velocity: expected a list of 3 numbers [m/s], got \"fast\"");
}

TEST(SceneParserTest, VectorOfWrongLength) {
  ExpectError(Replace(kBase3, "min: [-1, -1, -1]", "min: [-1, -1]"), 5, "domain.min",
              "expected a list of 3 numbers [m], got a list of 2 items");
  ExpectError(Replace(kBase2, "min: [-1, -1]", "min: [-1, -1, 0, 0]"), 5, "domain.min",
              "expected a list of 2 numbers (or 3 with z = 0) [m]");
}

TEST(SceneParserTest, NonZeroZIn2D) {
  ExpectError(kBase2 + "    velocity: [1, 0, 3]\n", 12, "bodies[0].velocity",
              "in 2-D the z component must be 0");
}

TEST(SceneParserTest, NegativeCellSize) {
  ExpectError(Replace(kBase3, "cell_size: 0.25", "cell_size: -0.25"), 4, "grid.cell_size",
              "must be > 0 [m], got -0.25");
}

TEST(SceneParserTest, CflAboveOne) {
  ExpectError(Replace(kBase3, "time: {end: 1.0}", "time: {end: 1.0, cfl: 1.5}"), 3, "time.cfl",
              "must be in (0, 1] [-], got 1.5");
}

TEST(SceneParserTest, UnknownShapeFunction) {
  ExpectError(Replace(kBase3, "{cell_size: 0.25}", "{cell_size: 0.25, shape_function: quadratic}"),
              4, "grid.shape_function",
              "unknown value 'quadratic' (expected one of: linear, gimp, quadratic_bspline, "
              "cubic_bspline)");
}

TEST(SceneParserTest, FlipRatioWithoutPicFlip) {
  ExpectError(Replace(kBase3, "{cell_size: 0.25}", "{cell_size: 0.25, flip_ratio: 0.9}"), 4,
              "grid.flip_ratio", "only to transfer: pic_flip");
}

TEST(SceneParserTest, UnknownWallType) {
  ExpectError(Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: {x-: sticky}}"), 5,
              "domain.walls.x-", "unknown value 'sticky' (expected one of: open, slip, no_slip)");
  ExpectError(Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: {x-: {type: glue}}}"),
              5, "domain.walls.x-.type", "unknown value 'glue'");
}

TEST(SceneParserTest, ZWallIn2D) {
  ExpectError(Replace(kBase2, "max: [2, 2]}", "max: [2, 2], walls: {z-: slip}}"), 5,
              "domain.walls.z-", "not allowed in 2-D");
}

TEST(SceneParserTest, NegativeFriction) {
  ExpectError(Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: {y-: {friction: -0.3}}}"),
              5, "domain.walls.y-.friction", "must be >= 0 [-], got -0.3");
}

TEST(SceneParserTest, BodyReferencesUnknownMaterial) {
  ExpectError(Replace(kBase3, "material: steel", "material: stee"), 10, "bodies[0].material",
              "unknown material 'stee' (defined: steel)");
}

TEST(SceneParserTest, BothElasticPairs) {
  ExpectError(Replace(kBase3, "poisson_ratio: 0.3}", "poisson_ratio: 0.3, bulk_modulus: 1e9}"), 7,
              "materials.steel", "not both");
}

TEST(SceneParserTest, MissingElasticConstants) {
  ExpectError(Replace(kBase3, ", youngs_modulus: 2.0e11, poisson_ratio: 0.3", ""), 7,
              "materials.steel", "missing elastic constants");
  ExpectError(Replace(kBase3, ", poisson_ratio: 0.3", ""), 7, "materials.steel.poisson_ratio",
              "missing required key 'poisson_ratio'");
}

TEST(SceneParserTest, PoissonRatioOneHalf) {
  ExpectError(Replace(kBase3, "poisson_ratio: 0.3", "poisson_ratio: 0.5"), 7,
              "materials.steel.poisson_ratio", "must be in (-1, 0.5) [-], got 0.5");
}

TEST(SceneParserTest, UnknownMaterialModel) {
  ExpectError(Replace(kBase3, "model: linear_elastic", "model: linear_elastic_2d"), 7,
              "materials.steel.model",
              "expected one of: linear_elastic, neo_hookean, j2, newtonian_fluid");
}

// Material line 7 of kBase3 with another model.
std::string WithMaterial(const std::string& material) {
  return Replace(kBase3,
                 "{model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3}",
                 material);
}

TEST(SceneParserTest, J2NeedsAYieldStress) {
  ExpectError(WithMaterial("{model: j2, density: 2710, bulk_modulus: 6.86e10, shear_modulus: 2.33e10}"),
              7, "materials.steel.yield_stress", "missing required key 'yield_stress'");
  ExpectError(WithMaterial("{model: j2, density: 2710, bulk_modulus: 6.86e10, shear_modulus: 2.33e10, "
                           "yield_stress: 0}"),
              7, "materials.steel.yield_stress", "must be > 0 [Pa], got 0");
}

TEST(SceneParserTest, J2NegativeHardening) {
  ExpectError(WithMaterial("{model: j2, density: 2710, youngs_modulus: 7e10, poisson_ratio: 0.33, "
                           "yield_stress: 6.1e7, kinematic_hardening: -1e9}"),
              7, "materials.steel.kinematic_hardening", "must be >= 0 [Pa], got -1e9");
}

TEST(SceneParserTest, PlasticKeysOnAnElasticModel) {
  ExpectError(Replace(kBase3, "poisson_ratio: 0.3}", "poisson_ratio: 0.3, yield_stress: 1e6}"), 7,
              "materials.steel.yield_stress", "unknown key 'yield_stress'");
}

TEST(SceneParserTest, FluidKeys) {
  const std::string water = "{model: newtonian_fluid, density: 997.5, bulk_modulus: 2e9, ";
  ExpectError(WithMaterial(water + "viscosity: 0.001, shear_modulus: 1e6}"), 7,
              "materials.steel.shear_modulus",
              "unknown key 'shear_modulus' (expected one of: model, density, bulk_modulus, "
              "viscosity, equation_of_state, tait_gamma, antilocking, bulk_viscosity, particle_shifting)");
  ExpectError(WithMaterial(water + "viscosity: -0.001}"), 7, "materials.steel.viscosity",
              "must be >= 0 [Pa s], got -0.001");
  ExpectError(WithMaterial(water + "equation_of_state: tait}"), 7, "materials.steel.viscosity",
              "missing required key 'viscosity'");
  ExpectError(WithMaterial(water + "viscosity: 0, equation_of_state: ideal_gas}"), 7,
              "materials.steel.equation_of_state",
              "unknown value 'ideal_gas' (expected one of: linear, tait)");
  ExpectError(WithMaterial(water + "viscosity: 0, tait_gamma: 7}"), 7, "materials.steel.tait_gamma",
              "tait_gamma applies only with equation_of_state: tait");
  ExpectError(WithMaterial(water + "viscosity: 0, equation_of_state: tait, tait_gamma: 1}"), 7,
              "materials.steel.tait_gamma", "must be > 1 [-], got 1");
}

// Bingham and frictional fluid (materials/bingham_fluid.h): mu_max needs mu_d > 0 for its
// default (1000 mu_d) and must exceed mu_d; the friction angle is in [0, 90) degrees.
TEST(SceneParserTest, ViscoplasticFluidKeys) {
  const std::string mud = "{model: bingham_fluid, density: 1800, bulk_modulus: 1.6e6, ";
  ExpectError(WithMaterial(mud + "yield_stress: 200}"), 7, "materials.steel",
              "max_viscosity (the cap mu_max [Pa s]) is required when viscosity is 0");
  ExpectError(WithMaterial(mud + "viscosity: 5, yield_stress: 200, max_viscosity: 5}"), 7,
              "materials.steel.max_viscosity", "max_viscosity must exceed viscosity");
  ExpectError(WithMaterial(mud + "viscosity: 5}"), 7, "materials.steel.yield_stress",
              "missing required key 'yield_stress'");
  ExpectError(WithMaterial(mud + "viscosity: 5, yield_stress: 200, tait_gamma: 7}"), 7,
              "materials.steel.tait_gamma", "tait_gamma applies only with equation_of_state: tait");
  const std::string sand = "{model: frictional_fluid, density: 1800, bulk_modulus: 1.6e6, ";
  ExpectError(WithMaterial(sand + "viscosity: 1, friction_angle_deg: 90}"), 7,
              "materials.steel.friction_angle_deg", "got 90");
  ExpectError(WithMaterial(sand + "viscosity: 1, friction_angle_deg: 30, cohesion: -1}"), 7,
              "materials.steel.cohesion", "must be >= 0 [Pa], got -1");
  const LoadedScene ok = LoadSceneFromString(
      WithMaterial(mud + "viscosity: 5, yield_stress: 200}"), "ok.yaml");
  EXPECT_EQ(std::get<BinghamFluidParams>(ok.model.materials[0].params).max_viscosity, 5000);
}

// Dense snow (materials/snow.h): M and xi > 0, 0 <= beta < 1, p0 >= 0, all required; the
// elastic pair as for every solid.
TEST(SceneParserTest, SnowKeys) {
  const std::string snow = "{model: snow, density: 300, youngs_modulus: 3e6, poisson_ratio: 0.3, ";
  const std::string rest = "hardening_factor: 0.5, consolidation_pressure: 3000";
  ExpectError(WithMaterial(snow + "cohesion_ratio: 0.3, " + rest + "}"), 7,
              "materials.steel.critical_state_slope", "missing required key 'critical_state_slope'");
  ExpectError(WithMaterial(snow + "critical_state_slope: 1.2, cohesion_ratio: 1, " + rest + "}"),
              7, "materials.steel.cohesion_ratio", "got 1");
  ExpectError(WithMaterial(snow + "critical_state_slope: 1.2, cohesion_ratio: 0.3, "
                                  "hardening_factor: 0, consolidation_pressure: 3000}"),
              7, "materials.steel.hardening_factor", "must be > 0 [-], got 0");
  ExpectError(WithMaterial(snow + "critical_state_slope: 1.2, cohesion_ratio: 0.3, "
                                  "hardening_factor: 0.5, consolidation_pressure: -1}"),
              7, "materials.steel.consolidation_pressure", "must be >= 0 [Pa], got -1");
  const LoadedScene ok = LoadSceneFromString(
      WithMaterial(snow + "critical_state_slope: 1.2, cohesion_ratio: 0.3, " + rest + "}"),
      "ok.yaml");
  const SnowParams& p = std::get<SnowParams>(ok.model.materials[0].params);
  EXPECT_EQ(p.critical_state_slope, 1.2);
  EXPECT_EQ(p.cohesion_ratio, 0.3);
  EXPECT_EQ(p.hardening_factor, 0.5);
  EXPECT_EQ(p.consolidation_pressure, 3000);
  EXPECT_NEAR(p.bulk_modulus, 3e6 / (3 * (1 - 2 * 0.3)), 1e-6);
}

// Matsuoka-Nakai (materials/matsuoka_nakai.h): a0 required in (0, 90) deg, a2 in 1/Pa; cross-key
// rules a4 <= a0, a3 > 0 when a1 > 0, peak friction angle < 89 deg.
TEST(SceneParserTest, MatsuokaNakaiKeys) {
  const std::string mn =
      "{model: matsuoka_nakai_dp, density: 2000, youngs_modulus: 7.5e7, poisson_ratio: 0.33, ";
  ExpectError(WithMaterial(mn + "a1: 7750, a3: 150}"), 7, "materials.steel.a0",
              "missing required key 'a0'");
  ExpectError(WithMaterial(mn + "a0: 20, a4: 25}"), 7, "materials.steel.a4",
              "a4 must not exceed a0");
  ExpectError(WithMaterial(mn + "a0: 20, a1: 7750, a3: 0, a4: 20}"), 7, "materials.steel.a3",
              "a3 must be > 0 when a1 > 0");
  ExpectError(WithMaterial(mn + "a0: 20, a1: 7750, a4: 20}"), 7, "materials.steel",
              "a3 must be > 0 when a1 > 0");  // a3 not written: the material is blamed
  ExpectError(WithMaterial(mn + "a0: 40, a1: 30000, a3: 150, a4: 20}"), 7, "materials.steel.a1",
              "must be < 89 deg");
  ExpectError(WithMaterial(mn + "a0: 20, dilation: none}"), 7, "materials.steel.dilation",
              "expected one of: stress_dilatancy, zero");
  const LoadedScene ok = LoadSceneFromString(
      WithMaterial(mn + "cohesion: 5000, a0: 20, a1: 7750, a2: 3.33e-7, a3: 150, a4: 20, a5: 300, "
                        "dilation: zero}"),
      "ok.yaml");
  const MatsuokaNakaiParams& p = std::get<MatsuokaNakaiParams>(ok.model.materials[0].params);
  EXPECT_EQ(p.potential, MatsuokaNakaiPotential::kDruckerPrager);
  EXPECT_EQ(p.cohesion, 5000);
  EXPECT_EQ(p.friction.a1, 7750);
  EXPECT_EQ(p.friction.a2, 3.33e-7);
  EXPECT_EQ(p.friction.a5, 300);
  EXPECT_TRUE(p.zero_dilation);
  const LoadedScene pure =
      LoadSceneFromString(WithMaterial(Replace(mn, "_dp", "") + "a0: 30}"), "ok.yaml");
  const MatsuokaNakaiParams& q = std::get<MatsuokaNakaiParams>(pure.model.materials[0].params);
  EXPECT_EQ(q.potential, MatsuokaNakaiPotential::kMatsuokaNakai);
  EXPECT_FALSE(q.zero_dilation);
}

// Mohr-Coulomb and Tresca (materials/mohr_coulomb.h): 0 <= psi <= phi < 90 deg, c >= 0; s_u > 0.
TEST(SceneParserTest, MohrCoulombAndTrescaKeys) {
  const std::string mc = "{model: mohr_coulomb, density: 2000, youngs_modulus: 5e7, poisson_ratio: 0.25, ";
  ExpectError(WithMaterial(mc + "friction_angle_deg: 30, dilation_angle_deg: 35}"), 7,
              "materials.steel.dilation_angle_deg", "dilation_angle_deg must not exceed friction_angle_deg");
  ExpectError(WithMaterial(mc + "cohesion: 1e4}"), 7, "materials.steel.friction_angle_deg",
              "missing required key 'friction_angle_deg'");
  ExpectError(WithMaterial(mc + "friction_angle_deg: 90}"), 7, "materials.steel.friction_angle_deg",
              "got 90");
  ExpectError(WithMaterial(mc + "friction_angle_deg: 30, cohesion: -1}"), 7,
              "materials.steel.cohesion", "must be >= 0 [Pa], got -1");
  const std::string tresca = "{model: tresca, density: 1800, youngs_modulus: 5e6, poisson_ratio: 0.3";
  ExpectError(WithMaterial(tresca + "}"), 7, "materials.steel.undrained_strength",
              "missing required key 'undrained_strength'");
  ExpectError(WithMaterial(tresca + ", undrained_strength: 0}"), 7,
              "materials.steel.undrained_strength", "must be > 0 [Pa], got 0");
  const LoadedScene ok = LoadSceneFromString(
      WithMaterial(mc + "friction_angle_deg: 30, dilation_angle_deg: 30, cohesion: 1e4}"), "ok.yaml");
  const MohrCoulombParams& p = std::get<MohrCoulombParams>(ok.model.materials[0].params);
  EXPECT_NEAR(std::sin(p.friction_angle), 0.5, 1e-15);  // degrees in the file, radians here
  EXPECT_EQ(p.dilation_angle, p.friction_angle);
  EXPECT_EQ(p.cohesion, 1e4);
  const LoadedScene clay = LoadSceneFromString(
      WithMaterial(tresca + ", undrained_strength: 2e4}"), "ok.yaml");
  EXPECT_EQ(std::get<TrescaParams>(clay.model.materials[0].params).undrained_strength, 2e4);
  // The tension cut-off: t >= 0, none (infinity) when not written.
  ExpectError(WithMaterial(mc + "friction_angle_deg: 30, tension_cutoff: -5}"), 7,
              "materials.steel.tension_cutoff", "must be >= 0 [Pa], got -5");
  ExpectError(WithMaterial(tresca + ", undrained_strength: 2e4, tension_cutoff: -1}"), 7,
              "materials.steel.tension_cutoff", "must be >= 0 [Pa], got -1");
  EXPECT_TRUE(std::isinf(p.tension_cutoff));
  const LoadedScene cut = LoadSceneFromString(
      WithMaterial(tresca + ", undrained_strength: 2e4, tension_cutoff: 5e3}"), "ok.yaml");
  EXPECT_EQ(std::get<TrescaParams>(cut.model.materials[0].params).tension_cutoff, 5e3);
}

TEST(SceneParserTest, GeostaticOnFluid) {
  const std::string text =
      WithMaterial("{model: newtonian_fluid, density: 1000, bulk_modulus: 2e7, viscosity: 0}") +
      "    initial_stress: {geostatic: {k0: 1}}\n" + "gravity: [0, -10, 0]\n";
  ExpectError(text, 12, "bodies[0].initial_stress.geostatic", "newtonian_fluid");
}

TEST(SceneParserTest, DuplicateBodyName) {
  ExpectError(kBase3 +
                  "  - name: block\n"
                  "    material: steel\n"
                  "    region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}\n",
              12, "bodies[1].name", "duplicate body name 'block' (also bodies[0])");
}

TEST(SceneParserTest, DuplicateKey) {
  ExpectError(kBase3 + "    material: steel\n", 12, "bodies[0].material", "duplicate key");
}

TEST(SceneParserTest, EmptyBodies) {
  const std::string text = kBase3.substr(0, kBase3.find("bodies:")) + "bodies: []\n";
  ExpectError(text, 8, "bodies", "expected a non-empty list of bodies");
}

TEST(SceneParserTest, YamlSyntaxErrorReportsItsLine) {
  const Caught c = Load(Replace(kBase3, "  - name: block\n", "  - name: block\n   bad: [1, 2\n"));
  ASSERT_TRUE(c.thrown);
  EXPECT_GE(c.line, 10) << c.what;
  EXPECT_LE(c.line, 12) << c.what;
  EXPECT_NE(c.what.find("YAML syntax error"), std::string::npos) << c.what;
}

TEST(SceneParserTest, SyntaxErrorFileReportsItsLine) {
  const std::string path = std::string(SURGE_SOURCE_DIR) + "/tests/data/bad_scenes/syntax_error.yaml";
  try {
    LoadScene(path);
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_GE(e.line(), 6) << e.what();
    EXPECT_LE(e.line(), 7) << e.what();
  }
}

TEST(SceneParserTest, UnknownKeyInFileNamesFileAndLine) {
  const std::string path = std::string(SURGE_SOURCE_DIR) + "/tests/data/bad_scenes/unknown_key.yaml";
  try {
    LoadScene(path);
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.line(), 11);
    EXPECT_EQ(e.key_path(), "bodies[0].veloctiy");
    EXPECT_NE(std::string(e.what()).find("unknown_key.yaml:11:5: bodies[0].veloctiy: unknown key"),
              std::string::npos)
        << e.what();
  }
}

TEST(SceneParserTest, UnreadableFile) {
  try {
    LoadScene("/nonexistent/dir/scene.yaml");
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/dir/scene.yaml");
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/scene.yaml: cannot read scene file"),
              std::string::npos)
        << e.what();
  }
}

TEST(SceneParserTest, MissingMeshFile) {
  const std::string path = std::string(SURGE_SOURCE_DIR) + "/tests/data/bad_scenes/missing_mesh.yaml";
  try {
    LoadScene(path);
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.line(), 12) << e.what();
    EXPECT_EQ(e.key_path(), "bodies[0].region.mesh.file") << e.what();
    EXPECT_NE(std::string(e.what()).find("no_such_mesh.stl"), std::string::npos) << e.what();
  }
}

TEST(SceneParserTest, OpenMeshIsRefused) {
  const std::string path = std::string(SURGE_SOURCE_DIR) + "/tests/data/bad_scenes/open_mesh.yaml";
  try {
    LoadScene(path);
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.line(), 12) << e.what();
    EXPECT_EQ(e.key_path(), "bodies[0].region.mesh.file") << e.what();
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
}

TEST(SceneParserTest, BodyOutsideDomain) {
  ExpectError(Replace(kBase3, "max: [1, 1, 1]}}", "max: [3, 1, 1]}}"), 11, "bodies[0].region",
              "outside the domain");
}

TEST(SceneParserTest, RegionWithoutParticles) {
  ExpectError(Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}",
                      "{sphere: {center: [0, 0, 0], radius: 0.01}}"),
              11, "bodies[0].region", "contains no particles");
}

TEST(SceneParserTest, RegionWithTwoShapes) {
  ExpectError(Replace(kBase3, "max: [1, 1, 1]}}", "max: [1, 1, 1]}, sphere: {center: [0, 0, 0], radius: 1}}"),
              11, "bodies[0].region", "expected exactly one of: box, sphere, cylinder, polygon, mesh");
}

TEST(SceneParserTest, GeostaticWithoutGravity) {
  ExpectError(kBase3 + "    initial_stress: {geostatic: {k0: 0.5}}\n", 12,
              "bodies[0].initial_stress.geostatic", "needs a non-zero gravity");
}

TEST(SceneParserTest, GeostaticOnNeoHookean) {
  const std::string text = Replace(kBase3, "model: linear_elastic", "model: neo_hookean") +
                           "    initial_stress: {geostatic: {k0: 0.5}}\n" + "gravity: [0, -10, 0]\n";
  ExpectError(text, 12, "bodies[0].initial_stress.geostatic", "neo_hookean");
}

TEST(SceneParserTest, JakyK0NeedsAFrictionAngle) {
  ExpectError(kBase3 + "    initial_stress: {geostatic: {k0: jaky}}\n" + "gravity: [0, -10, 0]\n",
              12, "bodies[0].initial_stress.geostatic.k0", "k0: jaky needs a material with a friction angle");
  ExpectError(kBase3 + "    initial_stress: {geostatic: {k0: 1-nu}}\n" + "gravity: [0, -10, 0]\n",
              12, "bodies[0].initial_stress.geostatic.k0", "(or jaky)");
}

TEST(SceneParserTest, JitterOutOfRange) {
  ExpectError(kBase3 + "    jitter: 1.0\n", 12, "bodies[0].jitter", "must be in [0, 1) [-], got 1.0");
}

TEST(SceneParserTest, ParticlesPerCellNotAnInteger) {
  ExpectError(kBase3 + "    particles_per_cell: 2.5\n", 12, "bodies[0].particles_per_cell",
              "expected an integer");
  ExpectError(kBase3 + "    particles_per_cell: 9\n", 12, "bodies[0].particles_per_cell",
              "must be an integer in [1, 8]");
}

TEST(SceneParserTest, BadDimensionAndName) {
  ExpectError(Replace(kBase3, "dimension: 3", "dimension: 4"), 2, "dimension",
              "must be an integer in [2, 3]");
  ExpectError(Replace(kBase3, "name: t\n", "name: my scene\n"), 1, "name",
              "may contain only letters");
}

TEST(SceneParserTest, CylinderAndMeshAre3DOnly) {
  ExpectError(Replace(kBase2, "{box: {min: [0, 0], max: [1, 1]}}",
                      "{cylinder: {base: [0, 0], top: [0, 1], radius: 0.2}}"),
              11, "bodies[0].region.cylinder", "3-D only");
}

TEST(SceneParserTest, SelfIntersectingPolygon) {
  ExpectError(Replace(kBase2, "{box: {min: [0, 0], max: [1, 1]}}",
                      "{polygon: {points: [[0, 0], [1, 1], [1, 0], [0, 1]]}}"),
              11, "bodies[0].region.polygon.points", "must be simple");
}

TEST(SceneParserTest, PolygonZIn2D) {
  ExpectError(Replace(kBase2, "{box: {min: [0, 0], max: [1, 1]}}",
                      "{polygon: {points: [[0, 0], [1, 0], [0, 1]], z: [0, 1]}}"),
              11, "bodies[0].region.polygon.z", "not allowed in 2-D");
}

TEST(SceneParserTest, TractionOnZFaceIn2D) {
  ExpectError(kBase2 + "    tractions: [{face: z+, traction: [0, 1]}]\n", 12,
              "bodies[0].tractions[0].face", "expected one of: x-, x+, y-, y+");
}

TEST(SceneParserTest, HugeRegionIsRefusedBeforeSeeding) {
  ExpectError(Replace(kBase3, "max: [1, 1, 1]}}", "max: [1.0e30, 1, 1]}}"), 11, "bodies[0].region",
              "particle lattice points");
  ExpectError(Replace(kBase3, "cell_size: 0.25", "cell_size: 1.0e-7"), 11, "bodies[0].region",
              "limit 4e8");
}

// Odd inputs: each must give a SceneError (never a crash or another exception type).
TEST(SceneParserTest, OddInputsGiveSceneErrors) {
  const std::vector<std::string> texts = {
      "hello",
      "[1, 2, 3]",
      "name: [a]\n",
      "? [a, b]\n: 1\n",
      Replace(kBase3, "materials:\n", "materials:\n  ? [x]\n  : {}\n"),
      Replace(kBase3, "  - name: block\n", "  - ~\n  - name: block\n"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", "{box: ~}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", "{}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", "[box]"),
      Replace(kBase3, "min: [0, 0, 0]", "min: [0, .nan, 0]"),
      Replace(kBase3, "min: [0, 0, 0]", "min: [0, .inf, 0]"),
      Replace(kBase3, "min: [0, 0, 0]", "min: [0, [0], 0]"),
      Replace(kBase3, "dimension: 3", "dimension: 99999999999999999999999"),
      Replace(kBase3, "time: {end: 1.0}", "time: &t {end: 1.0}\nalias: *t"),
      kBase3 + "    seed: -1\n",
      kBase3 + "    tractions: {face: x+}\n",
      kBase3 + "    tractions: [{face: x+}]\n",
      kBase3 + "    initial_stress: {hydrostatic: {}}\n",
      Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: {x-: {type: friction}}}"),
      Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: {x-: {type: no_slip, separable: false}}}"),
      Replace(kBase3, "max: [2, 2, 2]}", "max: [2, 2, 2], walls: [slip]}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}",
              "{polygon: {points: [[0, 0], [1, 0], [2, 0]], z: [0, 1]}}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}",
              "{polygon: {points: [[0, 0], [1, 0], [0, 1]], z: [1, 0]}}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}",
              "{mesh: {file: " + std::string(SURGE_SOURCE_DIR) + "/tests/data/meshes/not_a_mesh.obj}}"),
      Replace(kBase3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", "{mesh: {file: /}}"),
  };
  for (const std::string& text : texts) {
    try {
      LoadSceneFromString(text, "odd.yaml");
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("odd.yaml"), std::string::npos) << e.what();
    }
  }
}

TEST(SceneParserTest, EmptyScene) {
  const Caught c = Load("");
  ASSERT_TRUE(c.thrown);
  EXPECT_NE(c.what.find("the scene is empty"), std::string::npos) << c.what;
}

// --- --set overrides --------------------------------------------------------------------------

TEST(SceneOverrideTest, ListIndexOutOfRange) {
  const Caught c = Load(kBase3, {"bodies.3.velocity=[1,0,0]"});
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.file, "--set bodies.3.velocity=[1,0,0]");
  EXPECT_EQ(c.key_path, "bodies[3]");
  EXPECT_NE(c.what.find("out of range (the list has 1 items)"), std::string::npos) << c.what;
}

TEST(SceneOverrideTest, CreatedUnknownKeyIsCaught) {
  const Caught c = Load(kBase3, {"bodies.0.veloctiy=[1,0,0]"});
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.what.rfind("--set bodies.0.veloctiy=[1,0,0]: bodies[0].veloctiy: unknown key", 0), 0u)
      << c.what;
}

TEST(SceneOverrideTest, BadValueNamesTheOverride) {
  const Caught c = Load(kBase3, {"time.end=-1"});
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.what, "--set time.end=-1: time.end: must be > 0 [s], got -1");
}

TEST(SceneOverrideTest, MissingKeyUnderCreatedMapNamesTheOverride) {
  const Caught c = Load(kBase3, {"bodies.0.initial_stress.geostatic.kzero=1"});
  ASSERT_TRUE(c.thrown);
  EXPECT_EQ(c.file, "--set bodies.0.initial_stress.geostatic.kzero=1") << c.what;
}

TEST(SceneOverrideTest, MalformedOverride) {
  EXPECT_TRUE(Load(kBase3, {"time.end"}).thrown);
  EXPECT_TRUE(Load(kBase3, {"time..end=1"}).thrown);
  EXPECT_TRUE(Load(kBase3, {"time.end.x=1"}).thrown);
  EXPECT_TRUE(Load(kBase3, {"bodies.x.name=a"}).thrown);
}

TEST(SceneOverrideTest, SetsValuesBeforeValidation) {
  const LoadedScene s = LoadSceneFromString(
      kBase3, "s.yaml",
      {"bodies.0.velocity=[2,0,0]", "time.end=0.5", "grid.transfer=pic_flip",
       "grid.flip_ratio=0.9", "gravity=[0,-10,0]", "domain.walls.y-={friction: 0.4}"});
  EXPECT_EQ(s.model.time.end, 0.5);
  EXPECT_EQ(s.model.transfer, TransferScheme::kPicFlip);
  EXPECT_EQ(s.model.flip_ratio, 0.9);
  EXPECT_EQ(s.model.gravity, Vec3(0, -10, 0));
  EXPECT_EQ(s.model.walls[static_cast<int>(Face::kYMin)].kind, WallKind::kFriction);
  EXPECT_EQ(s.model.walls[static_cast<int>(Face::kYMin)].friction, 0.4);
  for (const Vec3& v : s.state.particles.v) EXPECT_EQ(v, Vec3(2, 0, 0));
  EXPECT_EQ(s.text, kBase3);  // the echo is the file, not the overridden tree
}

// --- resolved YAML ----------------------------------------------------------------------------

TEST(SceneResolvedYamlTest, FillsDefaults) {
  const LoadedScene s = LoadSceneFromString(kBase3, "s.yaml");
  for (const char* key : {"cfl: 0.4", "min_dt: 1e-12", "max_dt: 1e+30", "shape_function: quadratic_bspline",
                          "transfer: apic", "update: usl", "on_exit: remove", "x-: open",
                          "particles_per_cell: 2", "jitter: 0", "seed: 1", "every: 0", "energy: true"}) {
    EXPECT_NE(s.resolved_yaml.find(key), std::string::npos) << key << " in\n" << s.resolved_yaml;
  }
}

TEST(SceneResolvedYamlTest, RereadsToTheSameScene) {
  const std::string path = std::string(SURGE_SOURCE_DIR) + "/tests/data/scenes/full_3d.yaml";
  const LoadedScene a = LoadScene(path);
  const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
  EXPECT_EQ(a.state.particles.x, b.state.particles.x);
  EXPECT_EQ(a.state.particles.stress, b.state.particles.stress);
  EXPECT_EQ(a.state.particles.ext_force, b.state.particles.ext_force);
  EXPECT_EQ(a.model.dx, b.model.dx);
  EXPECT_EQ(a.model.flip_ratio, b.model.flip_ratio);
  ASSERT_EQ(a.model.materials.size(), b.model.materials.size());
  for (size_t m = 0; m < a.model.materials.size(); ++m) {
    EXPECT_EQ(WaveSpeed(a.model.materials[m]), WaveSpeed(b.model.materials[m]));
  }
  for (int f = 0; f < kFaceCount; ++f) {
    EXPECT_EQ(a.model.walls[f].kind, b.model.walls[f].kind);
    EXPECT_EQ(a.model.walls[f].friction, b.model.walls[f].friction);
    EXPECT_EQ(a.model.walls[f].separable, b.model.walls[f].separable);
  }
}

TEST(SceneResolvedYamlTest, RereadsPlasticAndFluidMaterials) {
  for (const std::string material :
       {"{model: j2, density: 2710, youngs_modulus: 7e10, poisson_ratio: 0.33, yield_stress: 6.1e7, "
        "isotropic_hardening: 2e8}",
        "{model: newtonian_fluid, density: 997.5, bulk_modulus: 2e7, viscosity: 0.001, "
        "equation_of_state: tait, tait_gamma: 7.15}",
        "{model: newtonian_fluid, density: 997.5, bulk_modulus: 2e7, viscosity: 0}",
        "{model: bingham_fluid, density: 1800, bulk_modulus: 1.6e6, viscosity: 5, "
        "yield_stress: 200}",
        "{model: frictional_fluid, density: 1800, bulk_modulus: 1.6e6, viscosity: 1, "
        "friction_angle_deg: 30, cohesion: 50, max_viscosity: 400, equation_of_state: tait}",
        "{model: snow, density: 300, youngs_modulus: 3e6, poisson_ratio: 0.3, "
        "critical_state_slope: 1.2, cohesion_ratio: 0.3, hardening_factor: 0.5, "
        "consolidation_pressure: 3000}"}) {
    const LoadedScene a = LoadSceneFromString(WithMaterial(material), "s.yaml");
    const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
    EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
    EXPECT_EQ(WaveSpeed(a.model.materials[0]), WaveSpeed(b.model.materials[0]));
  }
}

TEST(SceneResolvedYamlTest, RereadsIn2D) {
  const LoadedScene a = LoadSceneFromString(kBase2 + "    tractions: [{face: x+, traction: [5, 0]}]\n", "s.yaml");
  const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
  EXPECT_EQ(a.state.particles.ext_force, b.state.particles.ext_force);
}


// Scene arithmetic: `parameters:` and ${expr} values (docs/scene-reference.md).
TEST(SceneParametersTest, ExpressionsUseParametersAndOverrides) {
  const std::string text =
      Replace(kBase2, "max: [1, 1]}}", "max: [\"${l0}\", \"${a * l0}\"]}}") +
      "parameters: {a: 2, l0: 0.5, half: \"${l0 / 2}\"}\n";
  const LoadedScene s = LoadSceneFromString(text, "p.yaml");
  Real ymax = 0;
  for (const Vec3& x : s.state.particles.x) ymax = std::max(ymax, x.y());
  EXPECT_GT(ymax, 0.75);  // the box reaches y = a l0 = 1
  EXPECT_LT(ymax, 1.0);
  ASSERT_EQ(s.parameters.size(), 3u);
  EXPECT_EQ(s.parameters[2].second, 0.25);
  const LoadedScene tall = LoadSceneFromString(text, "p.yaml", {"parameters.a=3"});
  EXPECT_GT(tall.state.particles.size(), s.state.particles.size());
  const LoadedScene again = LoadSceneFromString(tall.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(again.resolved_yaml, tall.resolved_yaml);
}

TEST(SceneParametersTest, BadExpressionsNameLineAndKey) {
  const std::string base = Replace(kBase2, "max: [1, 1]}}", "max: [1, \"${a * b}\"]}}");
  ExpectError(base + "parameters: {a: 2}\n", 11, "bodies[0].region.box.max[1]",
              "cannot evaluate '${a * b}'");
  ExpectError(base + "parameters: {a: 2, 2b: 1}\n", 12, "parameters.2b", "parameter name");
  ExpectError(base + "parameters: {a: 2, b: [1]}\n", 12, "parameters.b",
              "expected a number or ${expression}");
  ExpectError(base + "parameters: {a: 2, b: \"${c}\", c: 1}\n", 12, "parameters.b",
              "cannot evaluate");
  ExpectError(kBase2 + "parameters: [1, 2]\n", 12, "parameters", "expected a map");
  const Caught c = Load(base + "parameters: {a: 2, b: 1}\n", {"parameters.b=x"});
  EXPECT_TRUE(c.thrown);
  EXPECT_EQ(c.file, "--set parameters.b=x");
}


TEST(SceneParserTest, SmoothCapDruckerPragerKeysAndJakyK0) {
  const std::string sc =
      "{model: drucker_prager_smooth_cap, density: 1950, bulk_modulus: 8.33e6, "
      "shear_modulus: 3.85e6, ";
  ExpectError(WithMaterial(sc + "friction_angle_deg: 20, yield_stress: 10, associativity: 1.5}"), 7,
              "materials.steel.associativity", "got 1.5");
  ExpectError(WithMaterial(sc + "friction_angle_deg: 20}"), 7, "materials.steel.yield_stress",
              "missing required key 'yield_stress'");
  ExpectError(WithMaterial(sc + "friction_angle: 20, yield_stress: 10}"), 7,
              "materials.steel.friction_angle", "unknown key 'friction_angle'");
  // k0: jaky = 1 - sin(30 deg) = 0.5: the horizontal stress is half the vertical one.
  const LoadedScene s = LoadSceneFromString(
      WithMaterial(sc + "friction_angle_deg: 30, yield_stress: 10}") +
          "    initial_stress: {geostatic: {k0: jaky}}\n" + "gravity: [0, -10, 0]\n",
      "ok.yaml");
  const Mat3& sigma = s.state.particles.stress[0].matrix();
  ASSERT_LT(sigma(1, 1), 0);
  EXPECT_NEAR(sigma(0, 0) / sigma(1, 1), 0.5, 1e-12);
  EXPECT_NE(s.resolved_yaml.find("k0: jaky"), std::string::npos) << s.resolved_yaml;
}


TEST(SceneParserTest, DruckerPragerKeys) {
  const std::string dp =
      "{model: drucker_prager, density: 2000, bulk_modulus: 2e7, shear_modulus: 1e7, ";
  ExpectError(WithMaterial(dp + "friction_angle_deg: 30, dilation_angle_deg: 35}"), 7,
              "materials.steel.dilation_angle_deg", "must not exceed friction_angle_deg");
  ExpectError(WithMaterial(dp + "friction_angle_deg: 0}"), 7, "materials.steel",
              "cohesion must be > 0");
  ExpectError(WithMaterial(dp + "cohesion: 1e4}"), 7, "materials.steel.friction_angle_deg",
              "missing required key 'friction_angle_deg'");
  const LoadedScene s = LoadSceneFromString(
      WithMaterial(dp + "friction_angle_deg: 30, cohesion: 1e4, isotropic_hardening: 1e6}"), "ok.yaml");
  const auto& p = std::get<DruckerPragerParams>(s.model.materials[0].params);
  EXPECT_NEAR(p.friction_slope, std::sqrt(2.0 / 3.0) * 2 * 0.5 / 2.5, 1e-15);  // (3.107) at 30 deg
  EXPECT_EQ(p.isotropic_hardening, 1e6);
}

TEST(SceneParserTest, AntiLockingKeysAndDefaults) {
  const std::string steel =
      "{model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3, ";
  ExpectError(WithMaterial(steel + "antilocking: {method: nodes}}"), 7,
              "materials.steel.antilocking.method", "expected one of: none, node, cell, hybrid, smoothing");
  ExpectError(WithMaterial(steel + "antilocking: {approach: volumetric}}"), 7,
              "materials.steel.antilocking.method", "missing required key 'method'");
  ExpectError(WithMaterial(steel + "antilocking: {method: hybrid, approach: constant_volumetric}}"),
              7, "materials.steel.antilocking.approach", "approach volumetric_deviatoric");
  ExpectError(WithMaterial(steel + "antilocking: {method: none, approach: constant_volumetric}}"),
              7, "materials.steel.antilocking.approach", "needs a control volume: method node, cell or hybrid");
  ExpectError(WithMaterial(steel + "antilocking: {method: cell, approach: as2}}"), 7,
              "materials.steel.antilocking.approach",
              "expected one of: volumetric, volumetric_deviatoric, constant_volumetric");
  {  // stress averaging with the full-tensor approaches (seed Table 4.1 steps 6-7, (4.35))
    const LoadedScene hb = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: hybrid, stress: true}}"), "ok.yaml");
    EXPECT_TRUE(hb.model.antilocking[0].stress);
    EXPECT_EQ(hb.model.antilocking[0].method, AntiLockingMethod::kHybrid);
    const LoadedScene as2 = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: cell, approach: volumetric_deviatoric, "
                             "stress: true}}"),
        "ok.yaml");
    EXPECT_TRUE(as2.model.antilocking[0].stress);
    EXPECT_EQ(as2.model.antilocking[0].approach, AntiLockingApproach::kVolumetricDeviatoric);
  }
  ExpectError(WithMaterial(steel + "antilocking: {method: smoothing, approach: volumetric_deviatoric}}"),
              7, "materials.steel.antilocking.approach", "smooths the volumetric strain only");
  ExpectError(WithMaterial(steel + "antilocking: {method: smoothing, stress: true}}"), 7,
              "materials.steel.antilocking.stress", "not for smoothing");
  {  // strain smoothing: the increment by default (Anura3D smooths the strain rate), total allowed
    const LoadedScene sm = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: smoothing}}"), "ok.yaml");
    EXPECT_EQ(sm.model.antilocking[0].method, AntiLockingMethod::kSmoothing);
    EXPECT_EQ(sm.model.antilocking[0].strain, AntiLockingStrain::kIncrement);
    EXPECT_EQ(LoadSceneFromString(sm.resolved_yaml, "again.yaml").model.antilocking[0].strain,
              AntiLockingStrain::kIncrement);
    const LoadedScene total = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: smoothing, strain: total}}"), "ok.yaml");
    EXPECT_EQ(total.model.antilocking[0].strain, AntiLockingStrain::kTotal);
  }
  {  // full-tensor approaches: parsed, hybrid defaults to volumetric_deviatoric, and both read
     // back from the resolved YAML
    const LoadedScene as3 = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: cell, approach: constant_volumetric}}"), "ok.yaml");
    EXPECT_EQ(as3.model.antilocking[0].approach, AntiLockingApproach::kConstantVolumetric);
    EXPECT_EQ(LoadSceneFromString(as3.resolved_yaml, "again.yaml").model.antilocking[0].approach,
              AntiLockingApproach::kConstantVolumetric);
    const LoadedScene nb = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: node, approach: volumetric_deviatoric}}"), "ok.yaml");
    EXPECT_EQ(nb.model.antilocking[0].approach, AntiLockingApproach::kVolumetricDeviatoric);
    const LoadedScene hb = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: hybrid}}"), "ok.yaml");
    EXPECT_EQ(hb.model.antilocking[0].method, AntiLockingMethod::kHybrid);
    EXPECT_EQ(hb.model.antilocking[0].approach, AntiLockingApproach::kVolumetricDeviatoric);
    EXPECT_NE(hb.resolved_yaml.find("antilocking: {method: hybrid, approach: volumetric_deviatoric"),
              std::string::npos) << hb.resolved_yaml;
  }
  ExpectError(WithMaterial(steel + "antilocking: {method: cell, smoothing: 1}}"), 7,
              "materials.steel.antilocking.smoothing", "unknown key 'smoothing'");
  ExpectError(WithMaterial(steel + "antilocking: {method: cell, strain: trial}}"), 7,
              "materials.steel.antilocking.strain", "expected one of: total, increment");
  ExpectError(WithMaterial(steel + "antilocking: node}"), 7, "materials.steel.antilocking",
              "expected a map with keys method, approach, fit, strain, stress");
  {  // fit: the seed's ConstantAntiLocking (constant) or TriLinearAntiLocking (linear, default)
    ExpectError(WithMaterial(steel + "antilocking: {method: cell, fit: linear}}"), 7,
                "materials.steel.antilocking.fit", "the volumetric approach (AS1) projects a constant");
    ExpectError(WithMaterial(steel + "antilocking: {method: smoothing, fit: linear}}"), 7,
                "materials.steel.antilocking.fit", "a linear fit of the trace alone needs method node");
    ExpectError(WithMaterial(steel + "antilocking: {method: none, fit: constant}}"), 7,
                "materials.steel.antilocking.fit", "needs a control volume");
    ExpectError(WithMaterial(steel + "antilocking: {method: cell, fit: quadratic}}"), 7,
                "materials.steel.antilocking.fit", "expected one of: linear, constant");
    const LoadedScene c = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: cell, approach: volumetric_deviatoric, fit: constant}}"),
        "ok.yaml");
    EXPECT_TRUE(c.model.antilocking[0].constant_fit);
    EXPECT_NE(c.resolved_yaml.find("fit: constant"), std::string::npos) << c.resolved_yaml;
    EXPECT_TRUE(LoadSceneFromString(c.resolved_yaml, "again.yaml").model.antilocking[0].constant_fit);
    const LoadedScene linear = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: node, approach: volumetric_deviatoric, fit: linear}}"),
        "ok.yaml");
    EXPECT_FALSE(linear.model.antilocking[0].constant_fit);
    EXPECT_FALSE(linear.model.antilocking[0].linear_trace);
    EXPECT_EQ(linear.resolved_yaml.find("fit:"), std::string::npos) << "written only when constant";
    // Node-based AS1 with the linear node fit of the trace (docs/antilocking.md, "Linear node
    // fit"): parsed, written back, read again.
    const LoadedScene trace = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: node, fit: linear}}"), "ok.yaml");
    EXPECT_TRUE(trace.model.antilocking[0].linear_trace);
    EXPECT_EQ(trace.model.antilocking[0].approach, AntiLockingApproach::kVolumetric);
    EXPECT_NE(trace.resolved_yaml.find("fit: linear"), std::string::npos) << trace.resolved_yaml;
    EXPECT_TRUE(
        LoadSceneFromString(trace.resolved_yaml, "again.yaml").model.antilocking[0].linear_trace);
    EXPECT_FALSE(LoadSceneFromString(WithMaterial(steel + "antilocking: {method: node}}"), "ok.yaml")
                     .model.antilocking[0]
                     .linear_trace);
  }
  ExpectError(WithMaterial(steel + "antilocking: {method: none, stress: true}}"), 7,
              "materials.steel.antilocking.stress", "needs a control volume");
  ExpectError(WithMaterial(steel + "antilocking: {method: cell, stress: 2}}"), 7,
              "materials.steel.antilocking.stress", "");
  {  // stress averaging: parsed, and written back to the resolved YAML only when on
    const LoadedScene avg = LoadSceneFromString(
        WithMaterial(steel + "antilocking: {method: node, stress: true}}"), "ok.yaml");
    EXPECT_TRUE(avg.model.antilocking[0].stress);
    EXPECT_TRUE(LoadSceneFromString(avg.resolved_yaml, "again.yaml").model.antilocking[0].stress);
  }
  // Defaults per class: solids none, the Newtonian fluid node-based on the total strain.
  const LoadedScene solid = LoadSceneFromString(kBase3, "ok.yaml");
  ASSERT_EQ(solid.model.antilocking.size(), 1u);
  EXPECT_EQ(solid.model.antilocking[0].method, AntiLockingMethod::kNone);
  const LoadedScene water = LoadSceneFromString(
      WithMaterial("{model: newtonian_fluid, density: 1000, bulk_modulus: 2e7, viscosity: 0}"),
      "ok.yaml");
  EXPECT_EQ(water.model.antilocking[0].method, AntiLockingMethod::kNode);
  EXPECT_EQ(water.model.antilocking[0].strain, AntiLockingStrain::kTotal);
  EXPECT_NE(water.resolved_yaml.find("antilocking: {method: node, approach: volumetric, strain: "
                                     "total}"),
            std::string::npos)
      << water.resolved_yaml;
  // The viscoplastic fluids: node-based on the step's increment (antilocking_test).
  for (const char* fluid : {"{model: bingham_fluid, density: 1800, bulk_modulus: 1.6e6, "
                            "viscosity: 5, yield_stress: 200}",
                            "{model: frictional_fluid, density: 1800, bulk_modulus: 1.6e6, "
                            "viscosity: 5, friction_angle_deg: 30}"}) {
    const LoadedScene mud = LoadSceneFromString(WithMaterial(fluid), "ok.yaml");
    EXPECT_EQ(mud.model.antilocking[0].method, AntiLockingMethod::kNode) << fluid;
    EXPECT_EQ(mud.model.antilocking[0].strain, AntiLockingStrain::kIncrement) << fluid;
    EXPECT_EQ(LoadSceneFromString(mud.resolved_yaml, "again.yaml").model.antilocking[0].strain,
              AntiLockingStrain::kIncrement);
  }
  const LoadedScene cell = LoadSceneFromString(
      WithMaterial(steel + "antilocking: {method: cell, strain: increment}}"), "ok.yaml");
  EXPECT_EQ(cell.model.antilocking[0].method, AntiLockingMethod::kCell);
  EXPECT_EQ(cell.model.antilocking[0].strain, AntiLockingStrain::kIncrement);
  // The resolved YAML reads back to the same choice.
  const LoadedScene again = LoadSceneFromString(cell.resolved_yaml, "again.yaml");
  EXPECT_EQ(again.model.antilocking[0].method, AntiLockingMethod::kCell);
  EXPECT_EQ(again.model.antilocking[0].strain, AntiLockingStrain::kIncrement);
}

// A body's own anti-locking replaces its material's (docs/antilocking.md, "Per body"): the same
// keys and errors, under the body's path; bodies of one material with different settings get
// separate particle groups, each projected over its own particles.
TEST(SceneParserTest, AntiLockingPerBody) {
  const std::string water =
      "  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2e7, viscosity: 0}\n";
  const std::string three_bodies = Replace(kBase3, "bodies:\n", water + "bodies:\n") +
                                   "  - name: plain\n"
                                   "    material: water\n"
                                   "    region: {box: {min: [1.5, 1.5, 1.5], max: [2, 2, 2]}}\n"
                                   "    antilocking: {method: none}\n"
                                   "  - name: pool\n"
                                   "    material: water\n"
                                   "    region: {box: {min: [-1, -1, -1], max: [-0.5, -0.5, -0.5]}}\n";
  const LoadedScene s = LoadSceneFromString(three_bodies, "ok.yaml");
  // Materials steel (none) and water (node), then the body override.
  ASSERT_EQ(s.model.antilocking.size(), 3u);
  EXPECT_EQ(s.model.antilocking[1].method, AntiLockingMethod::kNode);
  EXPECT_EQ(s.model.antilocking[2].method, AntiLockingMethod::kNone);
  ASSERT_EQ(s.model.bodies.size(), 3u);
  EXPECT_EQ(s.model.bodies[0].antilocking, 0);  // steel's own
  EXPECT_EQ(s.model.bodies[1].antilocking, 2);  // the override
  EXPECT_EQ(s.model.bodies[2].antilocking, 1);  // water's own
  // Groups: steel; water with its own setting (body "pool"); water with the override ("plain").
  ASSERT_EQ(s.state.groups.size(), 3u);
  const Particles& P = s.state.particles;
  const int expected_body[3] = {0, 2, 1}, expected_setting[3] = {0, 1, 2};
  for (size_t g = 0; g < 3; ++g) {
    const MaterialGroup& group = s.state.groups[g];
    EXPECT_EQ(group.AntiLockingIndex(), expected_setting[g]) << "group " << g;
    ASSERT_LT(group.begin, group.end) << "group " << g;
    for (size_t p = group.begin; p < group.end; ++p) ASSERT_EQ(P.body[p], expected_body[g]);
  }
  EXPECT_EQ(s.state.groups.back().end, P.size());
  // Written back to the resolved YAML only for the body that overrides, and read back.
  EXPECT_NE(s.resolved_yaml.find("antilocking: {method: none, approach: volumetric, strain: total}"),
            std::string::npos)
      << s.resolved_yaml;
  const LoadedScene again = LoadSceneFromString(s.resolved_yaml, "again.yaml");
  ASSERT_EQ(again.model.antilocking.size(), 3u);
  EXPECT_EQ(again.model.bodies[1].antilocking, 2);
  EXPECT_EQ(again.model.antilocking[2].method, AntiLockingMethod::kNone);
  // The same checks as a material's, with the body's path.
  ExpectError(kBase3 + "    antilocking: {approach: volumetric}\n", 12, "bodies[0].antilocking.method",
              "missing required key 'method'");
  ExpectError(kBase3 + "    antilocking: {method: nodes}\n", 12, "bodies[0].antilocking.method",
              "expected one of: none, node, cell, hybrid, smoothing");
  ExpectError(kBase3 + "    antilocking: {method: smoothing, stress: true}\n", 12,
              "bodies[0].antilocking.stress", "not for smoothing");
  ExpectError(kBase3 + "    antilocking: node\n", 12, "bodies[0].antilocking",
              "expected a map with keys method, approach, fit, strain, stress");
}

TEST(SceneParserTest, DampingKeys) {
  // damping: {local, until} at the top level (line 12, appended).
  ExpectError(kBase3 + "damping: {local: 1.0}\n", 12, "damping.local", "must be in [0, 1) [-]");
  ExpectError(kBase3 + "damping: {until: 2}\n", 12, "damping.local", "missing required key 'local'");
  ExpectError(kBase3 + "damping: {local: 0.7, until: 0}\n", 12, "damping.until", "must be > 0 [s]");
  ExpectError(kBase3 + "damping: {local: 0.7, alpha: 0.7}\n", 12, "damping.alpha",
              "unknown key 'alpha'");
  const LoadedScene off = LoadSceneFromString(kBase3, "ok.yaml");
  EXPECT_EQ(off.model.damping.alpha, 0);
  EXPECT_EQ(off.resolved_yaml.find("damping"), std::string::npos) << off.resolved_yaml;
  const LoadedScene on = LoadSceneFromString(kBase3 + "damping: {local: 0.7, until: 0.5}\n", "ok.yaml");
  EXPECT_EQ(on.model.damping.alpha, 0.7);
  EXPECT_EQ(on.model.damping.At(0.49), 0.7);
  EXPECT_EQ(on.model.damping.At(0.5), 0);
  const LoadedScene again = LoadSceneFromString(on.resolved_yaml, "again.yaml");
  EXPECT_EQ(again.model.damping.alpha, 0.7);
  EXPECT_EQ(again.model.damping.until, 0.5);
  const LoadedScene always = LoadSceneFromString(kBase3 + "damping: {local: 0.1}\n", "ok.yaml");
  EXPECT_EQ(always.model.damping.At(1e9), 0.1);
  EXPECT_FALSE(always.model.damping.Equilibrium());
  EXPECT_EQ(always.resolved_yaml.find("equilibrium"), std::string::npos);
  // equilibrium: release at static equilibrium (Anura3D §6.4), defaults 1e-3 and 1e-4.
  const std::string g = "gravity: [0, -9.81, 0]\n";
  const LoadedScene eq =
      LoadSceneFromString(kBase3 + g + "damping: {local: 0.7, equilibrium: {}}\n", "ok.yaml");
  EXPECT_TRUE(eq.model.damping.Equilibrium());
  EXPECT_EQ(eq.model.damping.force_ratio, 1e-3);
  EXPECT_EQ(eq.model.damping.energy_ratio, 1e-4);
  const LoadedScene eq2 = LoadSceneFromString(
      kBase3 + g + "damping: {local: 0.7, until: 2, equilibrium: {force_ratio: 5e-4, energy_ratio: 1e-6}}\n",
      "ok.yaml");
  const LoadedScene eq_again = LoadSceneFromString(eq2.resolved_yaml, "again.yaml");
  EXPECT_EQ(eq_again.model.damping.force_ratio, 5e-4);
  EXPECT_EQ(eq_again.model.damping.energy_ratio, 1e-6);
  EXPECT_EQ(eq_again.model.damping.until, 2);
  ExpectError(kBase3 + g + "damping: {local: 0.7, equilibrium: {force: 1e-3}}\n", 13,
              "damping.equilibrium.force", "unknown key 'force'");
  ExpectError(kBase3 + g + "damping: {local: 0.7, equilibrium: {energy_ratio: -1}}\n", 13,
              "damping.equilibrium.energy_ratio", "must be > 0");
  ExpectError(kBase3 + g + "damping: {local: 0, equilibrium: {}}\n", 13, "damping.equilibrium",
              "needs local > 0");
  ExpectError(kBase3 + "damping: {local: 0.7, equilibrium: {}}\n", 12, "damping.equilibrium",
              "needs a non-zero gravity");
}

TEST(SceneParserTest, MassScalingKeys) {
  // mass_scaling: {factor, until} at the top level (line 12, appended).
  ExpectError(kBase3 + "mass_scaling: {factor: 0.5}\n", 12, "mass_scaling.factor", "must be >= 1 [-]");
  ExpectError(kBase3 + "mass_scaling: {until: 2}\n", 12, "mass_scaling.factor",
              "missing required key 'factor'");
  ExpectError(kBase3 + "mass_scaling: {factor: 10, until: -1}\n", 12, "mass_scaling.until",
              "must be > 0 [s]");
  ExpectError(kBase3 + "mass_scaling: {factor: 10, beta: 2}\n", 12, "mass_scaling.beta",
              "unknown key 'beta'");
  ExpectError(kBase3 + "mass_scaling: 10\n", 12, "mass_scaling", "expected a map");
  const LoadedScene off = LoadSceneFromString(kBase3, "ok.yaml");
  EXPECT_EQ(off.model.mass_scaling.factor, 1);
  EXPECT_EQ(off.resolved_yaml.find("mass_scaling"), std::string::npos) << off.resolved_yaml;
  const LoadedScene on = LoadSceneFromString(kBase3 + "mass_scaling: {factor: 25, until: 0.5}\n", "ok.yaml");
  EXPECT_EQ(on.model.mass_scaling.At(0.49), 25);
  EXPECT_EQ(on.model.mass_scaling.At(0.5), 1);
  const LoadedScene again = LoadSceneFromString(on.resolved_yaml, "again.yaml");
  EXPECT_EQ(again.model.mass_scaling.factor, 25);
  EXPECT_EQ(again.model.mass_scaling.until, 0.5);
}

TEST(SceneParserTest, ParticleShiftingKey) {
  const std::string water =
      "{model: newtonian_fluid, density: 1000, bulk_modulus: 2e6, viscosity: 0.001, ";
  ExpectError(WithMaterial(water + "particle_shifting: 3}"), 7,
              "materials.steel.particle_shifting", "true or false");
  // Its node volumes are the quadratic B-spline's integrals.
  ExpectError(Replace(WithMaterial(water + "particle_shifting: true}"), "grid: {cell_size: 0.25}",
                      "grid: {cell_size: 0.25, shape_function: linear}"),
              7, "materials.steel.particle_shifting", "quadratic_bspline");
  const LoadedScene off = LoadSceneFromString(WithMaterial(water + "particle_shifting: false}"), "ok.yaml");
  EXPECT_FALSE(off.model.materials[0].particle_shifting);
  EXPECT_EQ(off.resolved_yaml.find("particle_shifting"), std::string::npos);
  const LoadedScene on = LoadSceneFromString(WithMaterial(water + "particle_shifting: true}"), "ok.yaml");
  EXPECT_TRUE(on.model.materials[0].particle_shifting);
  const LoadedScene again = LoadSceneFromString(on.resolved_yaml, "again.yaml");
  EXPECT_TRUE(again.model.materials[0].particle_shifting);
}

TEST(SceneParserTest, BulkViscosityKeys) {
  const std::string steel =
      "{model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3, ";
  ExpectError(WithMaterial(steel + "bulk_viscosity: {quadratic: -1}}"), 7,
              "materials.steel.bulk_viscosity.quadratic", "must be in [0, 10] [-]");
  ExpectError(WithMaterial(steel + "bulk_viscosity: {linear: 2}}"), 7,
              "materials.steel.bulk_viscosity.linear", "must be in [0, 1] [-]");
  ExpectError(WithMaterial(steel + "bulk_viscosity: {q1: 1}}"), 7,
              "materials.steel.bulk_viscosity.q1", "unknown key 'q1'");
  ExpectError(WithMaterial(steel + "bulk_viscosity: {quadratic: 0, linear: 0}}"), 7,
              "materials.steel.bulk_viscosity", "both 0");
  ExpectError(WithMaterial(steel + "bulk_viscosity: 1.5}"), 7, "materials.steel.bulk_viscosity",
              "expected a map");
  const LoadedScene off = LoadSceneFromString(kBase3, "ok.yaml");
  EXPECT_FALSE(off.model.bulk_viscosity[0].enabled);
  EXPECT_EQ(off.resolved_yaml.find("bulk_viscosity"), std::string::npos);
  const LoadedScene defaults = LoadSceneFromString(WithMaterial(steel + "bulk_viscosity: {}}"), "ok.yaml");
  EXPECT_TRUE(defaults.model.bulk_viscosity[0].enabled);
  EXPECT_EQ(defaults.model.bulk_viscosity[0].quadratic, 1.5);
  EXPECT_EQ(defaults.model.bulk_viscosity[0].linear, 0.06);
  const LoadedScene set =
      LoadSceneFromString(WithMaterial(steel + "bulk_viscosity: {quadratic: 1.2, linear: 0.1}}"), "ok.yaml");
  const LoadedScene again = LoadSceneFromString(set.resolved_yaml, "again.yaml");
  EXPECT_TRUE(again.model.bulk_viscosity[0].enabled);
  EXPECT_EQ(again.model.bulk_viscosity[0].quadratic, 1.2);
  EXPECT_EQ(again.model.bulk_viscosity[0].linear, 0.1);
}

}  // namespace
}  // namespace surge

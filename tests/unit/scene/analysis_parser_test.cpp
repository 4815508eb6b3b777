// Scene section `analysis` (docs/scene-reference.md; issue #6): a valid section reaches the Model
// with its defaults filled in, the resolved YAML reads back to itself, and every bad key or value
// is a SceneError naming the file, line and key path.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_spec.h"

namespace surge {
namespace {

// A column impact in miniature: line 13 is the first appended line.
const std::string kScene =
    "name: col\n"                                                                   //  1
    "dimension: 3\n"                                                                //  2
    "time: {end: 0.1}\n"                                                            //  3
    "gravity: [0, -10, 0]\n"                                                        //  4
    "grid: {cell_size: 0.25}\n"                                                     //  5
    "domain: {min: [0, 0, 0], max: [4, 2, 2], walls: {y-: slip}}\n"                 //  6
    "materials:\n"                                                                  //  7
    "  sand: {model: linear_elastic, density: 1950, bulk_modulus: 1.0e6, shear_modulus: 1.0e5}\n"
    "bodies:\n"                                                                     //  9
    "  - {name: surge, material: sand, region: {box: {min: [0, 0, 0], max: [1, 0.75, 2]}}, "
    "velocity: [2, 0, 0], initial_stress: {geostatic: {k0: 0.4}}}\n"                // 10
    "obstacles:\n"                                                                  // 11
    "  - {name: column, shape: {box: {min: [2, -0.5, -0.5], max: [2.5, 2.5, 1.5]}}}\n";  // 12

struct Caught {
  bool thrown = false;
  std::string what, key_path;
  int line = 0;
};

Caught Load(const std::string& text) {
  Caught c;
  try {
    LoadSceneFromString(text, "a.yaml");
  } catch (const SceneError& e) {
    c = {true, e.what(), e.key_path(), e.line()};
  }
  return c;
}

void ExpectError(const std::string& analysis, int line, const std::string& key_path,
                 const std::string& fragment) {
  const Caught c = Load(kScene + analysis);
  ASSERT_TRUE(c.thrown) << "no SceneError for:\n" << analysis;
  EXPECT_EQ(c.line, line) << c.what;
  EXPECT_EQ(c.key_path, key_path) << c.what;
  EXPECT_NE(c.what.find("a.yaml:" + std::to_string(line) + ":"), std::string::npos) << c.what;
  EXPECT_NE(c.what.find(fragment), std::string::npos) << c.what;
}

TEST(AnalysisParserTest, DefaultsFromTheScene) {
  const LoadedScene s = LoadSceneFromString(kScene + "analysis: {face: x-}\n", "a.yaml");
  const AnalysisSettings& a = s.model.analysis;
  EXPECT_EQ(a.structure, "column");  // the first obstacle
  EXPECT_EQ(a.face, "x-");
  EXPECT_FALSE(a.component);  // normal for an axis face, decided by the analysis
  EXPECT_EQ(*a.reference.density, 1950);
  EXPECT_EQ(*a.reference.velocity, 2);
  EXPECT_EQ(*a.reference.k0, 0.4);
  EXPECT_EQ(*a.reference.gravity, 10);
  EXPECT_EQ(*a.reference.width, 1.5);   // z extent of the column inside the domain (0 .. 1.5)
  EXPECT_EQ(*a.reference.height, 0.75);  // the body's box along gravity
  EXPECT_FALSE(a.reference.area);
  EXPECT_EQ(a.smoothing.kind, SmoothingKind::kNone);
  EXPECT_EQ(a.steady_state.average, 0.1);
  EXPECT_EQ(a.steady_state.min_window, 0.5);
  EXPECT_EQ(a.steady_state.tolerance, 0.02);
  // Without the section the same defaults apply (the structure, no face).
  const LoadedScene plain = LoadSceneFromString(kScene, "a.yaml");
  EXPECT_EQ(plain.model.analysis.structure, "column");
  EXPECT_EQ(plain.model.analysis.face, "");
  EXPECT_FALSE(plain.model.analysis.reference.width);  // no face: no box width
  EXPECT_EQ(plain.resolved_yaml.find("analysis"), std::string::npos);
}

TEST(AnalysisParserTest, FullSectionAndRoundTrip) {
  const std::string text =
      kScene +
      "analysis:\n"
      "  structure: domain\n"
      "  face: y-\n"
      "  component: y\n"
      "  reference: {velocity: 1.5, density: 2000, width: 2, height: 3, area: 5, k0: 0.5, gravity: 9.81}\n"
      "  smoothing: {low_pass: 20, order: 1}\n"
      "  steady_state: {average: 0.2, min_window: 0.3, tolerance: 0.05, window: [0.02, 0.09]}\n";
  const LoadedScene s = LoadSceneFromString(text, "a.yaml");
  const AnalysisSettings& a = s.model.analysis;
  EXPECT_EQ(a.structure, "domain");
  EXPECT_EQ(*a.component, ForceComponent::kY);
  EXPECT_EQ(*a.reference.area, 5);
  EXPECT_EQ(*a.reference.gravity, 9.81);
  EXPECT_EQ(a.smoothing.kind, SmoothingKind::kLowPass);
  EXPECT_EQ(a.smoothing.cutoff, 20);
  EXPECT_EQ(a.smoothing.order, 1);
  EXPECT_EQ((*a.steady_state.window)[1], 0.09);
  const LoadedScene b = LoadSceneFromString(s.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, s.resolved_yaml);
  for (const char* smoothing : {"none", "{moving_average: 0.05}", "{exponential: 0.01}"}) {
    const LoadedScene c = LoadSceneFromString(
        kScene + "analysis: {smoothing: " + smoothing + "}\n", "a.yaml");
    const LoadedScene d = LoadSceneFromString(c.resolved_yaml, "resolved.yaml");
    EXPECT_EQ(d.resolved_yaml, c.resolved_yaml) << smoothing;
  }
}

TEST(AnalysisParserTest, BadKeysAndValues) {
  ExpectError("analysis: {structure: column, colour: red}\n", 13, "analysis.colour",
              "unknown key 'colour' (expected one of: structure, face, component, reference");
  ExpectError("analysis: {structure: pier}\n", 13, "analysis.structure",
              "unknown structure 'pier' (expected one of: domain, column)");
  ExpectError("analysis: {face: w-}\n", 13, "analysis.face",
              "structure 'column' has no face 'w-' (its faces: x-, x+, y-, y+, z-, z+)");
  ExpectError("analysis: {component: sideways}\n", 13, "analysis.component",
              "unknown value 'sideways' (expected one of: x, y, z, normal, magnitude)");
  ExpectError("analysis: {component: normal}\n", 13, "analysis.component",
              "component normal needs an axis face");
  ExpectError("analysis:\n  reference: {velocity: 1, speed: 2}\n", 14, "analysis.reference.speed",
              "unknown key 'speed'");
  ExpectError("analysis:\n  reference: {density: -5}\n", 14, "analysis.reference.density",
              "must be > 0 [kg/m^3]");
  ExpectError("analysis:\n  smoothing: {moving_average: 0.1, exponential: 0.1}\n", 14,
              "analysis.smoothing", "expected exactly one of: moving_average, exponential, low_pass");
  ExpectError("analysis:\n  smoothing: {moving_average: 0.1, order: 2}\n", 14,
              "analysis.smoothing.order", "order applies only to low_pass");
  ExpectError("analysis:\n  smoothing: {low_pass: 20, order: 3}\n", 14,
              "analysis.smoothing.order", "must be an integer in [1, 2]");
  ExpectError("analysis:\n  smoothing: gaussian\n", 14, "analysis.smoothing",
              "expected none or a map");
  ExpectError("analysis:\n  steady_state: {tolerance: 0}\n", 14, "analysis.steady_state.tolerance",
              "must be in (0, 1]");
  ExpectError("analysis:\n  steady_state: {window: [2, 1]}\n", 14, "analysis.steady_state.window",
              "t1 must exceed t0");
  ExpectError("analysis:\n  steady_state: {plateau: 1}\n", 14, "analysis.steady_state.plateau",
              "unknown key 'plateau' (expected one of: average, min_window, tolerance, window)");
}

TEST(AnalysisParserTest, TwoDimensionalWidthIsPerMetre) {
  const std::string scene2 =
      "name: d\n"
      "dimension: 2\n"
      "time: {end: 0.1}\n"
      "gravity: [0, -9.81]\n"
      "grid: {cell_size: 0.25}\n"
      "domain: {min: [0, 0], max: [4, 2], walls: {x-: slip}}\n"
      "materials:\n"
      "  water: {model: neo_hookean, density: 1000, bulk_modulus: 1.0e6, shear_modulus: 1.0e5}\n"
      "bodies:\n"
      "  - {name: w, material: water, region: {box: {min: [0, 0], max: [1, 1]}}}\n";
  const LoadedScene s = LoadSceneFromString(scene2 + "analysis: {face: x-}\n", "a.yaml");
  EXPECT_EQ(s.model.analysis.structure, "domain");  // no obstacles or sensors
  EXPECT_EQ(*s.model.analysis.reference.width, 1);
  EXPECT_FALSE(s.model.analysis.reference.velocity);  // at rest: no default
  try {
    LoadSceneFromString(scene2 + "analysis: {reference: {width: 2}}\n", "a.yaml");
    ADD_FAILURE() << "no error for a 2-D width";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.key_path(), "analysis.reference.width");
    EXPECT_NE(std::string(e.what()).find("per metre of thickness"), std::string::npos) << e.what();
  }
  const Caught z = Load(scene2 + "analysis: {component: z}\n");
  EXPECT_TRUE(z.thrown);
  EXPECT_EQ(z.key_path, "analysis.component");
}

}  // namespace
}  // namespace surge

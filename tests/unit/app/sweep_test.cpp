// Sweep files (src/scene/sweep.cpp): product and list expansion, case names, linked parameters,
// strict errors with file, line and key; the case record; the summary.json flattener; and the
// shipped example sweeps load case by case. The runner is covered by sweep_cli_test.sh.
#include "scene/sweep.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "scene/scene.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Texts(const SweepCase& c) {
  std::vector<std::string> t;
  for (const SweepOverride& o : c.overrides) t.push_back(o.text);
  return t;
}

// The SceneError a sweep text raises, as "file:line:column: key: message".
std::string ErrorOf(const std::string& text) {
  try {
    ParseSweepText(text, "s.yaml", "/scenes");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SweepFile, ProductExpandsInFileOrderFirstParameterSlowest) {
  const SweepSpec s = ParseSweepText(R"(
base: ../scenes/x.yaml
set: {time.end: 0.5}
parameters:
  wc: [1, 2.5, 6]
  materials.sand.friction_angle_deg: [10, 30]
threads_per_case: 2
)", "sweeps/col.yaml", "/data/study/sweeps");
  EXPECT_EQ(s.base, "/data/study/scenes/x.yaml");
  EXPECT_EQ(s.out, "results/col");
  EXPECT_EQ(s.mode, SweepMode::kProduct);
  EXPECT_EQ(s.threads_per_case, 2);
  ASSERT_EQ(s.cases.size(), 6u);
  EXPECT_EQ(s.columns, (std::vector<std::string>{"wc", "materials.sand.friction_angle_deg"}));
  EXPECT_EQ(s.cases[0].name, "case_000_wc=1_friction_angle_deg=10");
  EXPECT_EQ(s.cases[3].name, "case_003_wc=2.5_friction_angle_deg=30");
  EXPECT_EQ(s.cases[5].index, 5);
  EXPECT_EQ(s.cases[3].values, (std::vector<std::string>{"2.5", "30"}));
  // The sweep-wide set first; a name without dots is a scene parameter.
  EXPECT_EQ(Texts(s.cases[3]), (std::vector<std::string>{"time.end=0.5", "parameters.wc=2.5",
                                                         "materials.sand.friction_angle_deg=30"}));
  EXPECT_EQ(s.cases[3].overrides[1].line, 5);  // the value's position, for errors
}

TEST(SweepFile, ListValuesAndIndexedPathsMakeReadableNames) {
  const SweepSpec s = ParseSweepText(R"(
base: a.yaml
out: /data/out
parameters:
  bodies.0.velocity: [[1, 0], [2, 0.5]]
  obstacles.0.shape.box.max.2: [3]
)", "s.yaml", "d");
  ASSERT_EQ(s.cases.size(), 2u);
  EXPECT_EQ(s.out, "/data/out");
  EXPECT_EQ(s.cases[1].name, "case_001_velocity=2_0.5_max2=3");
  EXPECT_EQ(s.cases[1].values[0], "[2, 0.5]");
  EXPECT_EQ(Texts(s.cases[1])[0], "bodies.0.velocity=[2, 0.5]");
}

TEST(SweepFile, LinkedParameterSetsSeveralKeysWithOneValue) {
  const SweepSpec s = ParseSweepText(R"(
base: a.yaml
parameters:
  width:
    values: [1, 2]
    set: {obstacles.0.shape.box.min.2: "${3 - width/2}", obstacles.0.shape.box.max.2: "${3 + width/2}"}
  phi: [20]
)", "s.yaml", ".");
  ASSERT_EQ(s.cases.size(), 2u);
  EXPECT_EQ(s.cases[1].name, "case_001_width=2_phi=20");
  EXPECT_EQ(Texts(s.cases[1]),
            (std::vector<std::string>{"parameters.width=2", "obstacles.0.shape.box.min.2=${3 - width/2}",
                                      "obstacles.0.shape.box.max.2=${3 + width/2}", "parameters.phi=20"}));
}

// The linked overrides reach the scene: its expressions see the new parameter.
TEST(SweepFile, LinkedParameterShapesTheScene) {
  const SweepSpec s = ParseSweepText(R"(
base: sweep_tiny_2d.yaml
parameters:
  width:
    values: [0.3, 0.5]
    set: {bodies.0.region.box.max.0: "${0.1 + width}"}
)", "s.yaml", std::string(SURGE_SOURCE_DIR) + "/tests/data/scenes");
  ASSERT_EQ(s.cases.size(), 2u);
  for (size_t c = 0; c < 2; ++c) {
    const LoadedScene scene = LoadScene(s.base, Texts(s.cases[c]));
    double x_max = 0;
    for (const Vec3& x : scene.state.particles.x) x_max = std::max(x_max, double(x[0]));
    const double right = 0.1 + (c == 0 ? 0.3 : 0.5);  // block's right face [m]
    EXPECT_LT(x_max, right) << s.cases[c].name;
    EXPECT_GT(x_max, right - 0.05) << s.cases[c].name;  // within a cell (dx = 0.05 m)
  }
}

TEST(SweepFile, ListModeColumnsAreTheUnionOfTheCasesKeys) {
  const SweepSpec s = ParseSweepText(R"(
base: a.yaml
cases:
  - {name: narrow, set: {parameters.wc: 1}}
  - {name: wide wall, set: {parameters.wc: 6, parameters.H: 2}}
  - {}
)", "s.yaml", ".");
  EXPECT_EQ(s.mode, SweepMode::kList);
  ASSERT_EQ(s.cases.size(), 3u);
  EXPECT_EQ(s.cases[0].name, "case_000_narrow");
  EXPECT_EQ(s.cases[1].name, "case_001_wide_wall");
  EXPECT_EQ(s.cases[2].name, "case_002");
  EXPECT_EQ(s.columns, (std::vector<std::string>{"parameters.wc", "parameters.H"}));
  EXPECT_EQ(s.cases[0].values, (std::vector<std::string>{"1", ""}));
  EXPECT_EQ(Texts(s.cases[1]), (std::vector<std::string>{"parameters.wc=6", "parameters.H=2"}));
}

TEST(SweepFile, BadInputNamesFileLineAndKey) {
  EXPECT_EQ(ErrorOf("base: a.yaml\nparameters: {wc: [1]}\nthreads: 2\n"),
            "s.yaml:3:1: threads: unknown key 'threads' (expected one of: base, out, mode, parameters, "
            "cases, set, threads_per_case, jobs)");
  EXPECT_EQ(ErrorOf("base: a.yaml\nparameters:\n  wc: []\n"),
            "s.yaml:3:7: parameters.wc: expected a non-empty list of values, got a list of 0 items");
  EXPECT_EQ(ErrorOf("base: a.yaml\nparameters:\n  w: {values: [1], sett: {}}\n"),
            "s.yaml:3:20: parameters.w.sett: unknown key 'sett' (expected one of: values, set)");
  EXPECT_EQ(ErrorOf("parameters: {wc: [1]}\n"),
            "s.yaml:1:1: base: missing: the base scene file (relative to the sweep file)");
  EXPECT_NE(ErrorOf("base: a.yaml\nparameters: {wc: [1]}\ncases: [{}]\n").find("s.yaml:3:8: cases: only in mode: list"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base: a.yaml\ncases: [{name: a}, {name: a}]\n").find("duplicate case name 'a'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base: a.yaml\nparameters: {wc: [1], parameters.wc: [2]}\n").find("sets parameters.wc"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base: a.yaml\nparameters: {wc: [{a: 1}]}\n").find("values must be"), std::string::npos);
  EXPECT_NE(ErrorOf("base: a.yaml\nmode: grid\nparameters: {wc: [1]}\n").find("s.yaml:2:7: mode: expected product or list"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base: a.yaml\nparameters: {wc: [1]}\nthreads_per_case: 0\n").find("threads_per_case"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base: [a\n").find("s.yaml:2:1: YAML syntax error"), std::string::npos);
}

TEST(SweepFile, CaseRecordRoundTrips) {
  const fs::path dir = fs::temp_directory_path() / "surge_sweep_record_test";
  fs::create_directories(dir);
  SweepCaseRecord r;
  r.name = "case_001_w=2";
  r.index = 1;
  r.scene = "/a/b.yaml";
  r.overrides = {"parameters.w=2", "bodies.0.velocity=[1, \"x\"]", "a.b=${3 - w/2}"};
  r.scene_digest = "00ff00ff00ff00ff";
  r.status = "completed";
  r.exit_code = 0;
  r.wall_seconds = 1.25;
  const std::string path = (dir / "case.yaml").string();
  WriteSweepCaseRecord(path, r);
  SweepCaseRecord back;
  ASSERT_TRUE(ReadSweepCaseRecord(path, back));
  EXPECT_EQ(back.name, r.name);
  EXPECT_EQ(back.index, 1);
  EXPECT_EQ(back.overrides, r.overrides);
  EXPECT_EQ(back.scene_digest, r.scene_digest);
  EXPECT_EQ(back.exit_code, 0);
  EXPECT_EQ(back.wall_seconds, 1.25);
  EXPECT_FALSE(ReadSweepCaseRecord((dir / "none.yaml").string(), back));
  fs::remove_all(dir);
}

TEST(SweepFile, SummaryJsonFlattensToDottedColumns) {
  const fs::path dir = fs::temp_directory_path() / "surge_sweep_flatten_test";
  fs::create_directories(dir);
  const std::string path = (dir / "summary.json").string();
  std::ofstream(path) << R"({"column": {"peak": {"force": [1.5, -2e3, 0], "time": 0.38}, "name": "x-",
  "faces": [{"n": 1}, {"n": 2}], "series": [1, 2, 3, 4], "none": null}, "ok": true})";
  const auto leaves = FlattenJsonFile(path);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"column.peak.force.x", "1.5"}, {"column.peak.force.y", "-2e3"}, {"column.peak.force.z", "0"},
      {"column.peak.time", "0.38"},   {"column.name", "x-"},           {"column.faces.0.n", "1"},
      {"column.faces.1.n", "2"},      {"column.series.0", "1"},        {"column.series.1", "2"},
      {"column.series.2", "3"},       {"column.series.3", "4"},        {"column.none", ""},
      {"ok", "true"}};
  EXPECT_EQ(leaves, expected);
  EXPECT_TRUE(FlattenJsonFile((dir / "missing.json").string()).empty());
  fs::remove_all(dir);
}

// Every case of the shipped sweeps loads (what `surge sweep --dry-run` checks before running).
TEST(SweepFile, ShippedSweepsLoadEveryCase) {
  for (const char* file : {"scenes/sweeps/column_impact_reduced.yaml", "tests/data/sweeps/tiny_product.yaml"}) {
    const SweepSpec s = LoadSweepFile(std::string(SURGE_SOURCE_DIR) + "/" + file);
    ASSERT_FALSE(s.cases.empty()) << file;
    for (const SweepCase& c : s.cases) {
      std::vector<std::string> texts = Texts(c);
      EXPECT_NO_THROW(LoadScene(s.base, texts)) << file << ": " << c.name;
    }
  }
}

}  // namespace
}  // namespace surge

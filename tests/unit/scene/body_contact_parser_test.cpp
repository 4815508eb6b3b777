// Scene key `body_contact` (issue #5; docs/scene-reference.md "body_contact"): pairs of bodies
// get their own velocity fields (Model::body_field, field_count), the first-listed body gives
// the normal; malformed pairs give SceneErrors naming file, line and key path; the resolved
// YAML reads back to itself.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scene/scene.h"

namespace surge {
namespace {

// Three bodies; the appended text starts on line 14.
std::string Scene(const std::string& tail, const std::string& update = "usl") {
  return "name: t\n"
         "dimension: 2\n"
         "time: {end: 1.0}\n"
         "grid: {cell_size: 0.25, update: " + update + "}\n"
         "domain: {min: [-1, -1], max: [3, 3]}\n"
         "materials:\n"
         "  soft: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e5, poisson_ratio: 0.3}\n"
         "bodies:\n"
         "  - {name: slab, material: soft, region: {box: {min: [0, 0], max: [2, 0.5]}}}\n"
         "  - {name: block, material: soft, region: {box: {min: [0.5, 0.5], max: [1, 1]}}}\n"
         "  - {name: lid, material: soft, region: {box: {min: [0.5, 1], max: [1, 1.25]}}}\n"
         "output: {every: 0}\n"
         "body_contact:\n" + tail;
}

void ExpectError(const std::string& text, int line, const std::string& key_path,
                 const std::string& fragment) {
  try {
    LoadSceneFromString(text, "bad.yaml");
    ADD_FAILURE() << "no SceneError for:\n" << text;
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "bad.yaml") << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.key_path(), key_path) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(BodyContactParserTest, PairedBodiesGetFieldsAndTheRestShareOne) {
  const LoadedScene s = LoadSceneFromString(
      Scene("  - {bodies: [block, slab], friction: 0.4}\n"), "s.yaml");
  ASSERT_EQ(s.model.body_contacts.size(), 1u);
  const BodyContact& c = s.model.body_contacts[0];
  EXPECT_EQ(c.body_a, 0);  // ordered by body index
  EXPECT_EQ(c.body_b, 1);
  EXPECT_EQ(c.normal_body, 1);  // the first-listed body: block
  EXPECT_EQ(c.friction, 0.4);
  EXPECT_TRUE(c.separable);
  EXPECT_TRUE(c.gap_test);  // the default for a separable pair
  EXPECT_EQ(s.model.body_field, (std::vector<int>{0, 1, 2}));  // lid shares the rest field
  EXPECT_EQ(s.model.field_count, 3);
}

TEST(BodyContactParserTest, NoBodyContactMeansOneField) {
  const LoadedScene s = LoadSceneFromString(
      Scene("  - {bodies: [slab, lid], separable: false}\n  - {bodies: [block, lid]}\n"), "s.yaml");
  EXPECT_EQ(s.model.field_count, 3);  // every body paired: no rest field
  EXPECT_FALSE(s.model.body_contacts[0].separable);
  EXPECT_FALSE(s.model.body_contacts[0].gap_test);  // a non-separable pair has none
  std::string text = Scene("");
  text.erase(text.find("body_contact:\n"));
  const LoadedScene one = LoadSceneFromString(text, "s.yaml");
  EXPECT_EQ(one.model.field_count, 0);
  EXPECT_TRUE(one.model.body_field.empty());
}

TEST(BodyContactParserTest, ResolvedYamlRereadsToItself) {
  const LoadedScene a = LoadSceneFromString(
      Scene("  - {bodies: [block, slab], friction: 0.25, separable: false}\n"), "s.yaml");
  EXPECT_NE(a.resolved_yaml.find("body_contact:"), std::string::npos) << a.resolved_yaml;
  const LoadedScene b = LoadSceneFromString(a.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(b.resolved_yaml, a.resolved_yaml);
  EXPECT_EQ(b.model.body_contacts[0].normal_body, 1);
  EXPECT_EQ(b.model.body_contacts[0].friction, 0.25);
  const LoadedScene off = LoadSceneFromString(
      Scene("  - {bodies: [block, slab], gap_test: false}\n"), "s.yaml");
  EXPECT_FALSE(off.model.body_contacts[0].gap_test);
  EXPECT_FALSE(LoadSceneFromString(off.resolved_yaml, "again.yaml").model.body_contacts[0].gap_test);
}

TEST(BodyContactParserTest, BadPairsNameFileLineAndKey) {
  ExpectError(Scene("  - {bodies: [slab, rock]}\n"), 14, "body_contact[0].bodies[1]",
              "no body is called 'rock' (bodies: slab, block, lid)");
  ExpectError(Scene("  - {bodies: [slab, slab]}\n"), 14, "body_contact[0].bodies",
              "cannot be in contact with itself");
  ExpectError(Scene("  - {bodies: [slab]}\n"), 14, "body_contact[0].bodies", "expected two body names");
  ExpectError(Scene("  - {bodies: [slab, block]}\n  - {bodies: [block, slab]}\n"), 15,
              "body_contact[1].bodies", "listed twice");
  ExpectError(Scene("  - {bodies: [slab, block], friction: -0.1}\n"), 14, "body_contact[0].friction",
              "");
  ExpectError(Scene("  - {bodies: [slab, block], mu: 0.1}\n"), 14, "body_contact[0].mu",
              "unknown key 'mu' (expected one of: bodies, friction, separable, gap_test)");
  ExpectError(Scene("  - {bodies: [slab, block], separable: false, gap_test: true}\n"), 14,
              "body_contact[0].gap_test", "needs separable: true");
  ExpectError(Scene("  {bodies: [slab, block]}\n"), 14, "body_contact", "expected a list of body pairs");
  ExpectError(Scene("  - {bodies: [slab, block]}\n", "musl"), 14, "body_contact[0]",
              "needs grid.update: usl");
}

}  // namespace
}  // namespace surge

// Scene builder: particle counts and volumes per region kind, mesh regions, geostatic stress,
// tractions, grouping by material, elastic constants, the Model fields.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include <Eigen/Eigenvalues>

#include "scene/scene.h"

namespace surge {
namespace {

// One body of `material` in `region` (flow-style YAML), cell size `dx`.
std::string OneBody(int dim, const std::string& region, double dx, const std::string& extra = "",
                    const std::string& top = "") {
  const std::string d = dim == 3 ? "{min: [-2, -2, -2], max: [2, 2, 2]}" : "{min: [-2, -2], max: [2, 2]}";
  return "name: t\n"
         "dimension: " + std::to_string(dim) + "\n"
         "time: {end: 1.0}\n"
         "grid: {cell_size: " + std::to_string(dx) + "}\n"
         "domain: " + d + "\n" + top +
         "materials:\n"
         "  soil: {model: linear_elastic, density: 2000, bulk_modulus: 1.0e7, shear_modulus: 5.0e6}\n"
         "bodies:\n"
         "  - name: b\n"
         "    material: soil\n"
         "    region: " + region + "\n" + extra;
}

Real TotalVolume(const LoadedScene& s) {
  return std::accumulate(s.state.particles.volume0.begin(), s.state.particles.volume0.end(), 0.0);
}
Real TotalMass(const LoadedScene& s) {
  return std::accumulate(s.state.particles.mass.begin(), s.state.particles.mass.end(), 0.0);
}

TEST(SceneBuilderTest, BoxGivesExactLatticeCountAndMass) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", 0.25), "s.yaml");
  const Particles& P = s.state.particles;
  ASSERT_EQ(P.size(), 512u);  // (1 / (0.25 / 2))^3
  EXPECT_NEAR(TotalMass(s), 2000.0 * 1.0, 1e-9);
  EXPECT_NEAR(TotalVolume(s), 1.0, 1e-12);
  EXPECT_EQ(P.x[0], Vec3(0.0625, 0.0625, 0.0625));  // (i + 1/2) s, x fastest
  EXPECT_EQ(P.x[1], Vec3(0.1875, 0.0625, 0.0625));
  for (size_t p = 0; p < P.size(); ++p) {
    EXPECT_EQ(P.F[p], Mat3::Identity());
    EXPECT_EQ(P.C[p], Mat3::Zero());
    EXPECT_TRUE(P.stress[p].isZero());
    EXPECT_EQ(P.strain[p], Mat3::Zero());
    EXPECT_EQ(P.id[p], static_cast<int64_t>(p));
    EXPECT_EQ(P.volume0[p], 0.125 * 0.125 * 0.125);
  }
}

TEST(SceneBuilderTest, LatticeIsAlignedWithTheGridNotTheBox) {
  // A box from 0.1 to 0.6 with s = 0.125: lattice points 0.1875, 0.3125, 0.4375, 0.5625.
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{box: {min: [0.1, 0.1, 0.1], max: [0.6, 0.6, 0.6]}}", 0.25), "s.yaml");
  EXPECT_EQ(s.state.particles.size(), 64u);
  EXPECT_EQ(s.state.particles.x[0], Vec3(0.1875, 0.1875, 0.1875));
}

TEST(SceneBuilderTest, Box2DIsPlaneStrain) {
  const LoadedScene s =
      LoadSceneFromString(OneBody(2, "{box: {min: [0, 0], max: [1, 0.5]}}", 0.1), "s.yaml");
  const Particles& P = s.state.particles;
  ASSERT_EQ(P.size(), 20u * 10u);
  for (size_t p = 0; p < P.size(); ++p) {
    EXPECT_EQ(P.x[p].z(), 0.0);
    EXPECT_NEAR(P.volume0[p], 0.05 * 0.05 * 1.0, 1e-18);  // s^2 x 1 m thickness
  }
  EXPECT_NEAR(TotalMass(s), 2000.0 * 0.5, 1e-9);
  EXPECT_EQ(s.model.dim, 2);
}

TEST(SceneBuilderTest, SphereVolumeMatches) {
  const Real r = 0.5;
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{sphere: {center: [0.1, 0.2, 0.3], radius: 0.5}}", 0.05), "s.yaml");
  const Real exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(TotalVolume(s) / exact, 1.0, 0.02);
  for (const Vec3& x : s.state.particles.x) EXPECT_LT((x - Vec3(0.1, 0.2, 0.3)).norm(), r);
}

TEST(SceneBuilderTest, DiskAreaMatchesIn2D) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(2, "{sphere: {center: [0, 0], radius: 0.5}}", 0.02), "s.yaml");
  EXPECT_NEAR(TotalVolume(s) / (std::numbers::pi * 0.25), 1.0, 0.02);
}

TEST(SceneBuilderTest, CylinderVolumeMatches) {
  const Real r = 0.3, length = 1.0;
  const Real exact = std::numbers::pi * r * r * length;
  const LoadedScene upright = LoadSceneFromString(
      OneBody(3, "{cylinder: {base: [0, -0.5, 0], top: [0, 0.5, 0], radius: 0.3}}", 0.05), "s.yaml");
  EXPECT_NEAR(TotalVolume(upright) / exact, 1.0, 0.03);
  const Real c = 1.0 / std::sqrt(3.0) / 2;
  const LoadedScene tilted = LoadSceneFromString(
      OneBody(3, "{cylinder: {base: [" + std::to_string(-c) + ", " + std::to_string(-c) + ", " +
                     std::to_string(-c) + "], top: [" + std::to_string(c) + ", " + std::to_string(c) +
                     ", " + std::to_string(c) + "], radius: 0.3}}",
              0.05),
      "s.yaml");
  EXPECT_NEAR(TotalVolume(tilted) / exact, 1.0, 0.03);
}

TEST(SceneBuilderTest, TriangleAreaMatchesIn2D) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(2, "{polygon: {points: [[0, 0], [1, 0], [0, 1]]}}", 0.02), "s.yaml");
  EXPECT_NEAR(TotalVolume(s) / 0.5, 1.0, 0.02);
  for (const Vec3& x : s.state.particles.x) EXPECT_LE(x.x() + x.y(), 1.0 + 1e-12);  // edge: either way
}

TEST(SceneBuilderTest, ExtrudedPolygonVolumeMatchesIn3D) {
  // An L-shape (area 0.75) extruded over 0.5 m; clockwise point order works as well.
  const LoadedScene s = LoadSceneFromString(
      OneBody(3,
              "{polygon: {points: [[0, 0], [0, 1], [0.5, 1], [0.5, 0.5], [1, 0.5], [1, 0]], "
              "z: [0, 0.5]}}",
              0.05),
      "s.yaml");
  EXPECT_NEAR(TotalVolume(s), 0.75 * 0.5, 1e-9);  // edges on lattice cell faces: exact
}

TEST(SceneBuilderTest, MeshCubeMatchesTheEquivalentBox) {
  const LoadedScene mesh =
      LoadScene(std::string(SURGE_SOURCE_DIR) + "/tests/data/scenes/mesh_cube.yaml");
  const LoadedScene box = LoadSceneFromString(
      OneBody(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", 0.25), "s.yaml");
  EXPECT_EQ(mesh.state.particles.size(), 512u);
  EXPECT_EQ(mesh.state.particles.x, box.state.particles.x);
}

TEST(SceneBuilderTest, MeshIsScaledAndTranslated) {
  const std::string file = std::string(SURGE_SOURCE_DIR) + "/tests/data/meshes/unit_cube.stl";
  const LoadedScene mesh = LoadSceneFromString(
      OneBody(3, "{mesh: {file: " + file + ", scale: 0.5, translate: [-0.5, 0, 0.25]}}", 0.25),
      "s.yaml");
  const LoadedScene box = LoadSceneFromString(
      OneBody(3, "{box: {min: [-0.5, 0, 0.25], max: [0, 0.5, 0.75]}}", 0.25), "s.yaml");
  EXPECT_EQ(mesh.state.particles.size(), 64u);
  EXPECT_EQ(mesh.state.particles.x, box.state.particles.x);
}

TEST(SceneBuilderTest, GeostaticStressAtKnownDepths) {
  // Top particle layer at y = 0.9375, free surface s/2 above it at y = 1.
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", 0.25,
              "    initial_stress: {geostatic: {k0: 0.5}}\n", "gravity: [0, -10, 0]\n"),
      "s.yaml");
  const Particles& P = s.state.particles;
  for (size_t p = 0; p < P.size(); ++p) {
    const Real depth = 1.0 - P.x[p].y();
    const Real sigma_v = -2000.0 * 10.0 * depth;
    EXPECT_NEAR(P.stress[p](1, 1), sigma_v, 1e-9);
    EXPECT_NEAR(P.stress[p](0, 0), 0.5 * sigma_v, 1e-9);
    EXPECT_NEAR(P.stress[p](2, 2), 0.5 * sigma_v, 1e-9);
    EXPECT_NEAR(P.stress[p](0, 1), 0.0, 1e-9);
  }
  EXPECT_NEAR(P.stress[0](1, 1), -2000.0 * 10.0 * 0.9375, 1e-9);  // bottom layer
}

TEST(SceneBuilderTest, GeostaticJ2StateReproducesTheStress) {
  std::string text = OneBody(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", 0.25,
                             "    initial_stress: {geostatic: {k0: 0.5}}\n", "gravity: [0, -10, 0]\n");
  text.replace(text.find("{model: linear_elastic"), std::string("{model: linear_elastic").size(),
               "{model: j2, yield_stress: 1.0e6");
  const LoadedScene s = LoadSceneFromString(text, "s.yaml");
  const Particles& P = s.state.particles;
  for (size_t p = 0; p < P.size(); ++p) {
    // Hencky elasticity at F = I: tau = sigma = K tr(eps) 1 + 2G dev(eps), eps = 1/2 ln b^e.
    Eigen::SelfAdjointEigenSolver<Mat3> eig(P.elastic_b[p].matrix());
    const Vec3 e = 0.5 * eig.eigenvalues().array().log();
    const Mat3 eps = eig.eigenvectors() * e.asDiagonal() * eig.eigenvectors().transpose();
    const Mat3 tau = 1.0e7 * eps.trace() * Mat3::Identity() + 2 * 5.0e6 * Dev(eps);
    EXPECT_LE((tau - P.stress[p].matrix()).norm(), 1e-9 * (1 + P.stress[p].matrix().norm())) << p;
    EXPECT_EQ(P.history.Get(p), History{});
  }
}

TEST(SceneBuilderTest, GeostaticStressFollowsAnInclinedGravity) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{box: {min: [0, 0, 0], max: [1, 1, 1]}}", 0.25,
              "    initial_stress: {geostatic: {k0: 0.4}}\n", "gravity: [3, -4, 0]\n"),
      "s.yaml");
  const Vec3 ghat(0.6, -0.8, 0);
  const Particles& P = s.state.particles;
  Real h_top = -1e9;
  for (const Vec3& x : P.x) h_top = std::max(h_top, -ghat.dot(x));
  h_top += 0.0625;
  for (size_t p = 0; p < P.size(); ++p) {
    const Real sigma_v = -2000.0 * 5.0 * (h_top + ghat.dot(P.x[p]));
    EXPECT_NEAR(ghat.dot(P.stress[p].matrix() * ghat), sigma_v, 1e-8);
    EXPECT_NEAR(P.stress[p].trace(), sigma_v * (1 + 2 * 0.4), 1e-8);
  }
}

TEST(SceneBuilderTest, TractionsActOnTheOutermostLayer) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(3, "{box: {min: [0, 0, 0], max: [1, 2, 0.5]}}", 0.25,
              "    tractions:\n"
              "      - {face: x+, traction: [0, -1000, 0]}\n"
              "      - {face: y-, traction: [0, 500, 0]}\n"),
      "s.yaml");
  const Particles& P = s.state.particles;
  Vec3 sum_x = Vec3::Zero(), sum_y = Vec3::Zero();
  for (size_t p = 0; p < P.size(); ++p) {
    const bool on_x = P.x[p].x() == 0.9375;
    const bool on_y = P.x[p].y() == 0.0625;
    Vec3 expected = Vec3::Zero();
    if (on_x) expected += Vec3(0, -1000, 0) * 0.125 * 0.125;  // t A_p, A_p = V_p / s = s^2
    if (on_y) expected += Vec3(0, 500, 0) * 0.125 * 0.125;
    EXPECT_EQ(P.ext_force[p], expected) << P.x[p].transpose();
    if (on_x) sum_x += Vec3(0, -1000, 0) * 0.125 * 0.125;
    if (on_y) sum_y += Vec3(0, 500, 0) * 0.125 * 0.125;
  }
  EXPECT_NEAR(sum_x.y(), -1000.0 * 2.0 * 0.5, 1e-9);  // traction x face area (2 x 0.5)
  EXPECT_NEAR(sum_y.y(), 500.0 * 1.0 * 0.5, 1e-9);
}

// Only the arrays the materials and tractions need are allocated (performance issue: bytes per
// particle): linear_elastic keeps the small strain, the plastic models b^e and history, the
// yield-stress fluids history, a body with tractions ext_force; APIC keeps C, FLIP does not.
TEST(SceneBuilderTest, ParticleArraysFollowTheMaterials) {
  struct Case {
    std::string material, extra;
    bool strain, elastic_b, history, ext_force;
    int history_slots;  // per particle, when history is held: the model's
  };
  const std::vector<Case> cases = {
      {"{model: linear_elastic, density: 2000, bulk_modulus: 1.0e7, shear_modulus: 5.0e6}", "",
       true, false, false, false, 0},
      {"{model: neo_hookean, density: 2000, bulk_modulus: 1.0e7, shear_modulus: 5.0e6}",
       "    tractions: [{face: y+, traction: [0, -200]}]\n", false, false, false, true, 0},
      {"{model: drucker_prager_smooth_cap, density: 2000, bulk_modulus: 8.33e6, "
       "shear_modulus: 3.85e6, friction_angle_deg: 30, yield_stress: 10}",
       "", false, true, true, false, 3},
      {"{model: drucker_prager, density: 2000, bulk_modulus: 5e6, shear_modulus: 3e6, "
       "friction_angle_deg: 30, dilation_angle_deg: 0, cohesion: 0}",
       "", false, true, true, false, 8},
      {"{model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e6, viscosity: 1.0e-3}", "", false,
       false, false, false, 0},
      {"{model: bingham_fluid, density: 1000, bulk_modulus: 2.0e6, viscosity: 1.0, yield_stress: 10}",
       "", false, false, true, false, 1},
  };
  for (const Case& c : cases) {
    std::string text = OneBody(2, "{box: {min: [0, 0], max: [1, 0.5]}}", 0.1, c.extra);
    const std::string le =
        "{model: linear_elastic, density: 2000, bulk_modulus: 1.0e7, shear_modulus: 5.0e6}";
    text.replace(text.find(le), le.size(), c.material);
    const LoadedScene s = LoadSceneFromString(text, "s.yaml");
    const Particles& P = s.state.particles;
    SCOPED_TRACE(c.material);
    ASSERT_EQ(P.size(), 200u);
    EXPECT_EQ(P.layout.affine, s.model.transfer == TransferScheme::kApic);
    EXPECT_EQ(P.C.size(), P.layout.affine ? P.size() : 0u);
    EXPECT_EQ(P.layout.strain, c.strain);
    EXPECT_EQ(P.layout.elastic_b, c.elastic_b);
    EXPECT_EQ(P.layout.history, c.history);
    EXPECT_EQ(P.layout.ext_force, c.ext_force);
    EXPECT_EQ(P.strain.size(), c.strain ? P.size() : 0u);
    EXPECT_EQ(P.elastic_b.size(), c.elastic_b ? P.size() : 0u);
    EXPECT_EQ(P.history.size(), c.history ? P.size() : 0u);
    if (c.history) {
      EXPECT_EQ(P.layout.history_slots, c.history_slots);
      EXPECT_EQ(P.history.stride(), c.history_slots);
    }
    EXPECT_EQ(P.ext_force.size(), c.ext_force ? P.size() : 0u);
  }
  for (const char* transfer : {"apic", "flip", "pic_flip"}) {
    std::string text = OneBody(2, "{box: {min: [0, 0], max: [1, 0.5]}}", 0.1);
    const std::string grid = "grid: {cell_size: ";
    text.replace(text.find(grid), grid.size(), std::string("grid: {transfer: ") + transfer + ", cell_size: ");
    const LoadedScene s = LoadSceneFromString(text, "s.yaml");
    EXPECT_EQ(s.state.particles.C.size(), std::string(transfer) == "apic" ? 200u : 0u) << transfer;
  }
}

TEST(SceneBuilderTest, TractionsSumToTractionTimesLengthIn2D) {
  const LoadedScene s = LoadSceneFromString(
      OneBody(2, "{box: {min: [0, 0], max: [1, 0.5]}}", 0.1,
              "    tractions: [{face: y+, traction: [0, -200]}]\n"),
      "s.yaml");
  Vec3 sum = Vec3::Zero();
  for (const Vec3& f : s.state.particles.ext_force) sum += f;
  EXPECT_NEAR(sum.y(), -200.0 * 1.0 * 1.0, 1e-9);  // x 1 m thickness
}

TEST(SceneBuilderTest, ParticlesAreGroupedByMaterialInStableOrder) {
  const std::string text =
      "name: t\ndimension: 3\ntime: {end: 1}\ngrid: {cell_size: 0.5}\n"
      "domain: {min: [0, 0, 0], max: [4, 4, 4]}\n"
      "materials:\n"
      "  steel: {model: linear_elastic, density: 7800, bulk_modulus: 1.6e11, shear_modulus: 8e10}\n"
      "  rubber: {model: neo_hookean, density: 1000, bulk_modulus: 1e6, shear_modulus: 3e5}\n"
      "  unused: {model: neo_hookean, density: 1000, bulk_modulus: 1e6, shear_modulus: 3e5}\n"
      "bodies:\n"
      "  - {name: a, material: rubber, region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}}\n"
      "  - {name: b, material: steel, region: {box: {min: [2, 0, 0], max: [3, 1, 1]}}, "
      "velocity: [1, 0, 0]}\n"
      "  - {name: c, material: rubber, region: {box: {min: [0, 2, 0], max: [1, 3, 0.5]}}}\n";
  const LoadedScene s = LoadSceneFromString(text, "s.yaml");
  const Particles& P = s.state.particles;
  ASSERT_EQ(P.size(), 64u + 64u + 32u);
  ASSERT_EQ(s.state.groups.size(), 2u);  // `unused` has no particles and no group
  EXPECT_EQ(s.state.groups[0].material, 0);
  EXPECT_EQ(s.state.groups[0].begin, 0u);
  EXPECT_EQ(s.state.groups[0].end, 64u);
  EXPECT_EQ(s.state.groups[1].material, 1);
  EXPECT_EQ(s.state.groups[1].begin, 64u);
  EXPECT_EQ(s.state.groups[1].end, 160u);
  // Group 0 is body b (seeded 64..127); group 1 is body a (0..63) then c (128..159).
  for (size_t p = 0; p < 64; ++p) {
    EXPECT_EQ(P.body[p], 1);
    EXPECT_EQ(P.material[p], 0);
    EXPECT_EQ(P.id[p], static_cast<int64_t>(64 + p));
    EXPECT_EQ(P.v[p], Vec3(1, 0, 0));
    EXPECT_EQ(P.mass[p], 7800.0 * 0.25 * 0.25 * 0.25);
  }
  for (size_t p = 64; p < 160; ++p) {
    EXPECT_EQ(P.material[p], 1);
    EXPECT_EQ(P.body[p], p < 128 ? 0 : 2);
    EXPECT_EQ(P.id[p], static_cast<int64_t>(p < 128 ? p - 64 : p));
  }
  ASSERT_EQ(s.model.bodies.size(), 3u);
  EXPECT_EQ(s.model.bodies[0].name, "a");
  EXPECT_EQ(s.model.bodies[0].material, 1);
  EXPECT_EQ(s.model.materials[2].name, "unused");
}

TEST(SceneBuilderTest, YoungsModulusAndPoissonRatioBecomeBulkAndShear) {
  const std::string text =
      "name: t\ndimension: 3\ntime: {end: 1}\ngrid: {cell_size: 0.5}\n"
      "domain: {min: [0, 0, 0], max: [1, 1, 1]}\n"
      "materials:\n"
      "  steel: {model: linear_elastic, density: 7800, youngs_modulus: 2.0e11, poisson_ratio: 0.3}\n"
      "  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 9.0e5, poisson_ratio: 0.25}\n"
      "bodies:\n"
      "  - {name: a, material: steel, region: {box: {min: [0, 0, 0], max: [1, 1, 1]}}}\n";
  const LoadedScene s = LoadSceneFromString(text, "s.yaml");
  const auto& steel = std::get<LinearElasticParams>(s.model.materials[0].params);
  EXPECT_DOUBLE_EQ(steel.bulk_modulus, 2.0e11 / (3 * (1 - 2 * 0.3)));
  EXPECT_DOUBLE_EQ(steel.shear_modulus, 2.0e11 / (2 * (1 + 0.3)));
  const auto& rubber = std::get<NeoHookeanParams>(s.model.materials[1].params);
  EXPECT_DOUBLE_EQ(rubber.bulk_modulus, 6.0e5);
  EXPECT_DOUBLE_EQ(rubber.shear_modulus, 3.6e5);
  EXPECT_EQ(s.model.materials[0].density, 7800.0);
}

TEST(SceneBuilderTest, FullSceneFillsTheModel) {
  const LoadedScene s = LoadScene(std::string(SURGE_SOURCE_DIR) + "/tests/data/scenes/full_3d.yaml");
  const Model& m = s.model;
  EXPECT_EQ(m.name, "elastic_drop_3d");
  EXPECT_EQ(m.dim, 3);
  EXPECT_EQ(m.dx, 0.1);
  EXPECT_EQ(m.shape, ShapeFunction::kCubicBspline);
  EXPECT_EQ(m.transfer, TransferScheme::kPicFlip);
  EXPECT_EQ(m.flip_ratio, 0.9);
  EXPECT_EQ(m.scheme, UpdateScheme::kMusl);
  EXPECT_EQ(m.gravity, Vec3(0, -9.81, 0));
  EXPECT_EQ(m.gravity_ramp, 0.1);
  EXPECT_EQ(m.time.end, 1.0);
  EXPECT_EQ(m.time.cfl, 0.4);
  EXPECT_EQ(m.time.min_dt, 1e-9);
  EXPECT_EQ(m.time.max_dt, 1e-3);
  EXPECT_EQ(m.time.fixed_dt, 0.0);
  EXPECT_EQ(m.domain_min, Vec3(-1, 0, -1));
  EXPECT_EQ(m.domain_max, Vec3(1, 2, 1));
  EXPECT_EQ(m.walls[0].kind, WallKind::kSlip);
  EXPECT_TRUE(m.walls[0].separable);
  EXPECT_EQ(m.walls[1].kind, WallKind::kSlip);
  EXPECT_FALSE(m.walls[1].separable);
  EXPECT_EQ(m.walls[2].kind, WallKind::kFriction);
  EXPECT_EQ(m.walls[2].friction, 0.3);
  EXPECT_EQ(m.walls[3].kind, WallKind::kOpen);
  EXPECT_EQ(m.walls[4].kind, WallKind::kNoSlip);
  EXPECT_EQ(m.walls[5].kind, WallKind::kOpen);
  EXPECT_EQ(m.exit_policy, ExitPolicy::kStop);
  EXPECT_EQ(m.output.every, 0.05);
  EXPECT_FALSE(m.output.vdb);
  EXPECT_TRUE(m.output.energy);
  ASSERT_EQ(m.bodies.size(), 5u);
  EXPECT_EQ(s.state.groups.size(), 2u);
  for (size_t b = 0; b < 5; ++b) {
    const auto n = std::count(s.state.particles.body.begin(), s.state.particles.body.end(),
                              static_cast<int32_t>(b));
    EXPECT_GT(n, 0) << m.bodies[b].name;
  }
}

TEST(SceneBuilderTest, JitterIsDeterministicAndBounded) {
  const std::string region = "{box: {min: [0, 0, 0], max: [1, 1, 1]}}";
  const LoadedScene plain = LoadSceneFromString(OneBody(3, region, 0.25), "s.yaml");
  const LoadedScene a = LoadSceneFromString(OneBody(3, region, 0.25, "    jitter: 0.5\n    seed: 7\n"), "s.yaml");
  const LoadedScene b = LoadSceneFromString(OneBody(3, region, 0.25, "    jitter: 0.5\n    seed: 7\n"), "s.yaml");
  const LoadedScene c = LoadSceneFromString(OneBody(3, region, 0.25, "    jitter: 0.5\n    seed: 8\n"), "s.yaml");
  ASSERT_EQ(a.state.particles.size(), plain.state.particles.size());
  EXPECT_EQ(a.state.particles.x, b.state.particles.x);
  EXPECT_NE(a.state.particles.x, c.state.particles.x);
  const Real s = 0.125;
  Vec3 mean = Vec3::Zero();
  for (size_t p = 0; p < a.state.particles.size(); ++p) {
    const Vec3 d = a.state.particles.x[p] - plain.state.particles.x[p];
    EXPECT_LE(d.cwiseAbs().maxCoeff(), 0.5 * 0.5 * s);
    mean += d;
  }
  mean /= static_cast<Real>(a.state.particles.size());
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.1 * s);  // centred, not biased
}

}  // namespace
}  // namespace surge

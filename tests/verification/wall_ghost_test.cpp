// Mirrored ghost nodes and the gap test at domain walls (domain.ghost_nodes, domain.gap_test;
// docs/walls.md).
// With quadratic (and cubic) B-splines a particle next to a wall also interpolates from the nodes
// beyond it. When those ghost nodes are only constrained like the node on the wall (normal inflow
// removed, the default `constrain`), the interpolated normal velocity on the wall plane is not
// zero, v(0) = N(-h) v_-h + N(0) v_0 + N(h) v_h = v_h / 8 for a particle on the plane, so
// particles keep moving into the wall and are put back on its plane by the domain exit stage.
// With `mirror` each ghost takes minus the normal velocity of its mirror image inside, the odd
// extension, so v(0) = 0 and a particle approaches the wall only asymptotically.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

#include "support/obstacle_checks.h"
#include "support/run_scene.h"

namespace surge {
namespace {

// The seed's 2-D dam break (scenes/dam_break_2d.yaml: a 0.057 x 0.114 m water column collapses
// along a slip floor, quadratic B-splines, APIC, USL) to 0.25 s, when the front has hit the far
// wall. Counts the particles that the domain exit stage put back on a wall plane (within 1e-12 m
// of it) and the nearest approach of the others.
struct Walls {
  int on_plane = 0;     // particles on a wall plane at the end
  Real nearest = 0;     // smallest distance of a particle off the planes [m]
  Real mass = 0, kinetic = 0;
};

Walls RunDamBreak(const std::string& ghosts) {
  LoadedScene scene = LoadScene(testing::ScenePath("dam_break_2d.yaml"),
                                {"domain.ghost_nodes=" + ghosts});
  const Real mass = testing::TotalMass(scene.state.particles);
  testing::RunUntil(scene, scene.model.time.end, [](const State&, const StepReport&) {});
  Walls w;
  w.nearest = 1e9;
  const Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p) {
    const Vec3& x = P.x[p];
    const Real d = std::min({x.x(), 0.456 - x.x(), x.y(), 0.228 - x.y()});
    if (d <= 1e-12) ++w.on_plane;
    else w.nearest = std::min(w.nearest, d);
    w.kinetic += 0.5 * P.mass[p] * P.v[p].squaredNorm();
  }
  w.mass = testing::TotalMass(P) / mass;
  std::printf("dam break, ghost nodes %-9s: %d of %zu particles on a wall plane, nearest other "
              "%.3e m, kinetic energy %.4e J/m\n",
              ghosts.c_str(), w.on_plane, P.size(), w.nearest, w.kinetic);
  return w;
}

TEST(WallGhostTest, MirroredGhostsKeepParticlesOffTheWallPlane) {
  const Walls constrained = RunDamBreak("constrain");
  const Walls mirrored = RunDamBreak("mirror");
  EXPECT_GT(constrained.on_plane, 0) << "the defect the mirror fixes: particles driven onto a wall";
  EXPECT_EQ(mirrored.on_plane, 0);
  EXPECT_GT(mirrored.nearest, 0);
  EXPECT_EQ(mirrored.mass, 1.0);  // no particle lost
}

// Gap test (domain.gap_test, docs/walls.md "Stand-off"): a 0.4 x 0.2 m elastic block (2 particles
// per 0.05 m cell per direction, so its particles' half-size is h / 4) dropped from 0.1 m onto a
// slip floor and damped to rest (local damping 0.3, 1.5 s). Without the gap test the floor acts as
// soon as the block's particles reach the floor nodes' support (1.5 h for quadratic B-splines) and
// the block rests on that node layer; with it, the floor acts once a particle is within 1.5 of its
// half-size of the plane. Returns the lowest particle's height [cells] and the mean floor force over
// the last 0.2 s / weight.
std::pair<Real, Real> DroppedBlock(const std::string& shape, bool gap_test) {
  const std::string text = R"(name: ghost_drop
dimension: 2
time: {end: 1.5, cfl: 0.3}
gravity: [0, -9.81]
grid: {cell_size: 0.05, shape_function: )" + shape + R"(, transfer: apic, update: usl}
domain:
  min: [0, 0]
  max: [1, 0.6]
  walls: {x-: slip, x+: slip, y-: slip}
  gap_test: )" + (gap_test ? "true" : "false") + R"(
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies:
  - {name: block, material: rubber, region: {box: {min: [0.3, 0.1], max: [0.7, 0.3]}}, particles_per_cell: 2}
damping: {local: 0.3}
)";
  LoadedScene scene = LoadSceneFromString(text, "ghost_drop.yaml");
  const Real weight = testing::TotalMass(scene.state.particles) * 9.81;
  Real force = 0;
  int n = 0;
  testing::RunUntil(scene, 1.5, [&](const State& s, const StepReport& r) {
    if (s.time < 1.3) return;
    force += -r.walls.force[int(Face::kYMin)].y();
    ++n;
  });
  Real lowest = 1e9;
  for (const Vec3& x : scene.state.particles.x) lowest = std::min(lowest, x.y());
  std::printf("dropped block, %s, gap test %s: lowest particle at rest %.3f h above the floor, "
              "floor force / weight %.5f\n",
              shape.c_str(), gap_test ? "on " : "off", lowest / 0.05, force / n / weight);
  return {lowest / 0.05, force / n / weight};
}

TEST(WallGhostTest, GapTestLetsADroppedBlockLandOnTheFloor) {
  for (const std::string shape : {"quadratic_bspline", "cubic_bspline"}) {
    const auto [off, off_force] = DroppedBlock(shape, false);
    const auto [on, on_force] = DroppedBlock(shape, true);
    EXPECT_GT(off, 1.2) << shape << ": the stand-off the gap test removes (measured 1.27 / 1.36 h)";
    // 1.5 particle half-sizes = 0.375 h: the block's surface 0.125 h above the plane
    EXPECT_LT(on, 0.38) << shape;
    EXPECT_GT(on, 0.25) << shape;  // and no particle on or through the plane
    EXPECT_NEAR(on_force, 1.0, 1e-3) << shape;
    EXPECT_NEAR(off_force, 1.0, 1e-3) << shape;
  }
}

std::string BoxScene(const std::string& ghosts) {
  return R"(name: ghost_box
dimension: 2
time: {end: 0.1}
gravity: [0, -9.81]
grid: {cell_size: 0.05, shape_function: quadratic_bspline}
domain:
  min: [0, 0]
  max: [1, 0.6]
  walls: {y-: slip}
  ghost_nodes: )" + ghosts + R"(
materials:
  rubber: {model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
bodies:
  - {name: block, material: rubber, region: {box: {min: [0.3, 0], max: [0.7, 0.2]}}}
)";
}

TEST(WallGhostTest, GhostNodesKeyIsParsedAndRefused) {
  EXPECT_EQ(LoadSceneFromString(BoxScene("mirror"), "ghost_drop.yaml").model.ghost_nodes, GhostNodes::kMirror);
  EXPECT_EQ(LoadSceneFromString(BoxScene("mirror_velocity"), "ghost_drop.yaml").model.ghost_nodes,
            GhostNodes::kMirrorVelocity);
  EXPECT_EQ(LoadSceneFromString(BoxScene("constrain"), "ghost_drop.yaml").model.ghost_nodes, GhostNodes::kConstrain);
  EXPECT_EQ(LoadSceneFromString(BoxScene("fold_all"), "ghost_drop.yaml").model.ghost_nodes, GhostNodes::kFoldAll);
  try {
    LoadSceneFromString(BoxScene("reflect"), "ghost_drop.yaml");
    FAIL() << "an unknown ghost_nodes value must be refused";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ghost_drop.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("domain.ghost_nodes"), std::string::npos) << what;
  }
  // domain.gap_test: a boolean
  EXPECT_FALSE(LoadSceneFromString(BoxScene("mirror\n  gap_test: false"), "ghost_drop.yaml").model.wall_gap_test);
  EXPECT_TRUE(LoadSceneFromString(BoxScene("mirror"), "ghost_drop.yaml").model.wall_gap_test);
  try {
    LoadSceneFromString(BoxScene("mirror\n  gap_test: sometimes"), "ghost_drop.yaml");
    FAIL() << "a gap_test that is not a boolean must be refused";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("domain.gap_test"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace surge

// Mirrored ghost nodes at domain walls (domain.ghost_nodes: mirror; docs/walls.md).
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
  EXPECT_TRUE(LoadSceneFromString(BoxScene("mirror"), "ghost_drop.yaml").model.mirror_ghost_nodes);
  EXPECT_FALSE(LoadSceneFromString(BoxScene("constrain"), "ghost_drop.yaml").model.mirror_ghost_nodes);
  try {
    LoadSceneFromString(BoxScene("reflect"), "ghost_drop.yaml");
    FAIL() << "an unknown ghost_nodes value must be refused";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ghost_drop.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("domain.ghost_nodes"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace surge

// Two colliding elastic disks (Sulsky, Chen & Schreyer 1994, §5): total energy (kinetic +
// strain) is conserved through the collision within 2 %, the disks really collide (kinetic energy
// dips) and rebound (velocities reverse), and momentum exchange is symmetric.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "support/run_scene.h"

namespace surge {
namespace {

TEST(TwoDisksTest, EnergyConservedThroughCollision) {
  LoadedScene scene = LoadScene(testing::ScenePath("two_disks_2d.yaml"));
  const EnergyRecord e0 = ComputeEnergy(scene.model, scene.state);
  ASSERT_GT(e0.kinetic, 0);
  Real max_drift = 0, min_kinetic = e0.kinetic;
  testing::RunUntil(scene, 4.0, [&](const State&, const StepReport& r) {
    const Real total = r.energy.kinetic + r.energy.strain;
    max_drift = std::max(max_drift, std::abs(total - e0.kinetic) / e0.kinetic);
    min_kinetic = std::min(min_kinetic, r.energy.kinetic);
  });
  RecordProperty("energy_drift", std::to_string(max_drift));
  std::printf("two disks: max |E - E0| / E0 = %.3f %%, min kinetic / E0 = %.3f\n", 100 * max_drift,
              min_kinetic / e0.kinetic);
  EXPECT_LT(max_drift, 0.02);
  EXPECT_LT(min_kinetic, 0.5 * e0.kinetic) << "the disks should have collided";

  // After the rebound each disk moves away from the other, symmetrically.
  Vec3 momentum[2] = {Vec3::Zero(), Vec3::Zero()};
  const Particles& P = scene.state.particles;
  for (size_t p = 0; p < P.size(); ++p) momentum[P.body[p]] += P.mass[p] * P.v[p];
  EXPECT_LT(momentum[0].x(), 0);
  EXPECT_GT(momentum[1].x(), 0);
  EXPECT_LT((momentum[0] + momentum[1]).norm(), 1e-10 * momentum[0].norm() + 1e-12);
}

}  // namespace
}  // namespace surge

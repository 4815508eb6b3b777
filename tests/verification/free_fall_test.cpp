// Free fall (shared/VALIDATION.md): with no contact, the centre of mass follows the discrete
// integrator exactly (to round-off): P2G/G2P conserve momentum and gravity acts on the grid, so
// v_cm,n+1 = v_cm,n + g dt_n and x_cm,n+1 = x_cm,n + dt_n v_cm,n+1; and it stays within the
// first-order time-integration error 1/2 |g| t max(dt) of x0 + v0 t + 1/2 g t^2.
#include <gtest/gtest.h>

#include "support/run_scene.h"

namespace surge {
namespace {

void CentreOfMass(const Particles& P, Vec3& x, Vec3& v) {
  Real m = 0;
  x.setZero();
  v.setZero();
  for (size_t p = 0; p < P.size(); ++p) {
    m += P.mass[p];
    x += P.mass[p] * P.x[p];
    v += P.mass[p] * P.v[p];
  }
  x /= m;
  v /= m;
}

TEST(FreeFallTest, CentreOfMassFollowsClosedForm) {
  for (const char* transfer : {"apic", "flip"}) {
    LoadedScene scene = LoadScene(testing::ScenePath("elastic_drop_3d.yaml"),
                                  {std::string("grid.transfer=") + transfer, "grid.cell_size=0.08"});
    const Vec3 g = scene.model.gravity;
    Vec3 x_ref, v_ref;
    CentreOfMass(scene.state.particles, x_ref, v_ref);
    const Vec3 x0 = x_ref, v0 = v_ref;
    Real max_dt = 0;
    // The block bottom is 0.5 m above the floor: it lands at t = sqrt(2 * 0.5 / 9.81) = 0.319 s.
    testing::RunUntil(scene, 0.25, [&](const State& s, const StepReport&) {
      v_ref += s.dt * g;
      x_ref += s.dt * v_ref;
      max_dt = std::max(max_dt, s.dt);
    });
    Vec3 x, v;
    CentreOfMass(scene.state.particles, x, v);
    const Real t = scene.state.time;
    EXPECT_LT((v - v_ref).norm(), 1e-11) << transfer;
    EXPECT_LT((x - x_ref).norm(), 1e-11) << transfer;
    const Vec3 closed = x0 + v0 * t + 0.5 * g * t * t;
    EXPECT_LT((x - closed).norm(), 0.5 * g.norm() * t * max_dt * 1.01) << transfer;
  }
}

}  // namespace
}  // namespace surge

// The health check's diagnostic (CheckStateStage, docs/stability.md "The health stop") on
// hand-built states: the field that went bad first in step order names the stage (v and x:
// grid_to_particle; F and J: grid_to_particle under USL, velocity_gradient under MUSL; stress:
// update_stress), the reported particle is the lowest index with that field for any thread count,
// and the message names the particle, material, body, the count and the likely cause.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <limits>
#include <string>

#include "step/stages.h"
#include "support/test_state.h"

namespace surge {
namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

Health Check(const Model& m, State& s, Real dt) {
  StepContext ctx;
  ctx.dt = dt;
  ctx.dx = m.dx;
  ctx.inv_dx = 1 / m.dx;
  Workspace w;
  StepReport r;
  CheckStateStage(m, ctx, s, w, r);
  return r.health;
}

struct Fixture {
  Model m = testing::SmallModel(2, ShapeFunction::kQuadraticBspline, TransferScheme::kApic, 0.1);
  State s = testing::RandomState(2, 1000, Vec3(0, 0, 0), 1.0, 0.1);
  Real dt_limit = 0;  // h / c of the rubber [s]
  Fixture() { dt_limit = m.dx / WaveSpeed(m.materials[0]); }
};

TEST(HealthCheckTest, HealthyStatePasses) {
  Fixture f;
  EXPECT_EQ(Check(f.m, f.s, 0.4 * f.dt_limit).status, HealthStatus::kOk);
}

TEST(HealthCheckTest, StressOnlyNamesUpdateStress) {
  Fixture f;
  f.s.particles.stress[700].v[3] = kNaN;  // xy
  f.s.particles.stress[300].v[1] = std::numeric_limits<Real>::infinity();  // yy
  const Health h = Check(f.m, f.s, 0.4 * f.dt_limit);
  EXPECT_EQ(h.status, HealthStatus::kNonFinite);
  EXPECT_EQ(h.stage, "update_stress");
  EXPECT_EQ(h.field, "stress");
  EXPECT_EQ(h.particle_id, 300);
  EXPECT_NE(h.detail.find("particle id 300 (material 'rubber', body 'body'"), std::string::npos) << h.detail;
  EXPECT_NE(h.detail.find("2 of 1000 particles unhealthy"), std::string::npos) << h.detail;
  EXPECT_NE(h.detail.find("Likely cause: material 'rubber' could not be updated"), std::string::npos)
      << h.detail;
}

// A bad velocity precedes a bad stress in the step: it is reported even at a higher index.
TEST(HealthCheckTest, EarliestFieldWinsOverLowerIndex) {
  Fixture f;
  f.s.particles.stress[10].v[0] = kNaN;  // xx
  f.s.particles.F[500](0, 0) = -1;  // det F = -1
  f.s.particles.v[900].x() = kNaN;
  const Health h = Check(f.m, f.s, 0.4 * f.dt_limit);
  EXPECT_EQ(h.stage, "grid_to_particle");
  EXPECT_EQ(h.field, "v");
  EXPECT_EQ(h.particle_id, 900);
  EXPECT_NE(h.detail.find("3 of 1000 particles unhealthy"), std::string::npos) << h.detail;
}

TEST(HealthCheckTest, InvertedParticleUnderMuslNamesVelocityGradient) {
  Fixture f;
  f.m.scheme = UpdateScheme::kMusl;
  f.s.particles.F[42](0, 0) = -0.5;  // det F = -0.5
  const Health h = Check(f.m, f.s, 0.4 * f.dt_limit);
  EXPECT_EQ(h.status, HealthStatus::kInvertedElement);
  EXPECT_EQ(h.stage, "velocity_gradient");
  EXPECT_EQ(h.field, "J");
  EXPECT_EQ(h.particle_id, 42);
  EXPECT_NE(h.detail.find("det F = J = -0.5"), std::string::npos) << h.detail;
  EXPECT_NE(h.detail.find("compressed through zero volume"), std::string::npos) << h.detail;
}

TEST(HealthCheckTest, FixedDtAboveTheLimitIsTheCause) {
  Fixture f;
  f.m.time.fixed_dt = 3 * f.dt_limit;
  f.s.particles.x[5].y() = kNaN;
  const Health h = Check(f.m, f.s, f.m.time.fixed_dt);
  EXPECT_EQ(h.field, "x");
  EXPECT_NE(h.detail.find("Likely cause: time.fixed_dt is above the CFL limit"), std::string::npos)
      << h.detail;
  EXPECT_NE(h.detail.find("Courant number 3 > 1"), std::string::npos) << h.detail;
}

// The same offender on 1 and 2 threads (the chunks are fixed, the choice is by index).
TEST(HealthCheckTest, OffenderIndependentOfThreadCount) {
  Fixture f;
  for (size_t p : {999u, 640u, 321u}) f.s.particles.stress[p].v[2] = kNaN;  // zz
  std::string one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = Check(f.m, f.s, 0.4 * f.dt_limit).detail;
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = Check(f.m, f.s, 0.4 * f.dt_limit).detail;
  }
  EXPECT_EQ(one, two);
  EXPECT_NE(one.find("particle id 321"), std::string::npos) << one;
}

}  // namespace
}  // namespace surge

// Frictional contact between MPM bodies on per-body velocity fields (issue #5; Bardenhagen et
// al. 2000; Anura3D manual §6.2; src/transfer/body_contact.cpp):
// - an elastic block on an elastic slab (both MPM), gravity tilted by theta: with friction mu <
//   tan(theta) the block slides at a = g (sin(theta) - mu cos(theta)) (the closed form of the
//   inclined plane), with mu > tan(theta) it sticks; without `body_contact` the two bodies
//   share one velocity field and the block cannot slide (the problem the fields fix);
// - the contact forces of the two fields are equal and opposite at every step, and the logged
//   force on the slab is the block's normal weight and mu times it;
// - two elastic disks colliding head-on with frictionless separable contact conserve momentum
//   to round-off and rebound.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "support/run_scene.h"

namespace surge {
namespace {

constexpr Real kG = 9.81;

// 2-D: a slab 0.2 m thick on a no-slip floor, a 0.25 x 0.25 m block on it; gravity tilted by
// theta towards +x (the incline's frame).
std::string InclineScene(Real theta_deg, const std::string& contact) {
  const Real th = theta_deg * M_PI / 180;
  return R"(name: block_on_slab
dimension: 2
time: {end: 1.0, cfl: 0.4}
gravity: [)" + std::to_string(kG * std::sin(th)) + ", " + std::to_string(-kG * std::cos(th)) + R"(]
grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0]
  max: [3, 1]
  walls: {x-: slip, x+: slip, y-: no_slip}
materials:
  stiff: {model: neo_hookean, density: 2000, youngs_modulus: 5.0e7, poisson_ratio: 0.3}
bodies:
  - name: slab
    material: stiff
    region: {box: {min: [0, 0], max: [3, 0.2]}}
    particles_per_cell: 2
  - name: block
    material: stiff
    region: {box: {min: [0.3, 0.2], max: [0.55, 0.45]}}
    particles_per_cell: 2
)" + contact;
}

// The same in 3-D: a slab two cells thick in z between slip walls (1.5 m long).
std::string InclineScene3D(Real theta_deg, const std::string& contact) {
  const Real th = theta_deg * M_PI / 180;
  return R"(name: block_on_slab_3d
dimension: 3
time: {end: 1.0, cfl: 0.4}
gravity: [)" + std::to_string(kG * std::sin(th)) + ", " + std::to_string(-kG * std::cos(th)) + R"(, 0]
grid: {cell_size: 0.05, shape_function: quadratic_bspline, transfer: apic, update: usl}
domain:
  min: [0, 0, 0]
  max: [1.5, 0.6, 0.1]
  walls: {x-: slip, x+: slip, y-: no_slip, z-: slip, z+: slip}
materials:
  stiff: {model: neo_hookean, density: 2000, youngs_modulus: 5.0e7, poisson_ratio: 0.3}
bodies:
  - name: slab
    material: stiff
    region: {box: {min: [0, 0, 0], max: [1.5, 0.2, 0.1]}}
    particles_per_cell: 2
  - name: block
    material: stiff
    region: {box: {min: [0.3, 0.2, 0], max: [0.55, 0.45, 0.1]}}
    particles_per_cell: 2
)" + contact;
}

struct BodyMotion {
  Real mass = 0;
  Vec3 momentum = Vec3::Zero();
  Vec3 centre = Vec3::Zero();
};

BodyMotion MotionOf(const Particles& P, int body) {
  BodyMotion b;
  for (size_t p = 0; p < P.size(); ++p) {
    if (P.body[p] != body) continue;
    b.mass += P.mass[p];
    b.momentum += P.mass[p] * P.v[p];
    b.centre += P.mass[p] * P.x[p];
  }
  b.centre /= b.mass;
  return b;
}

// Least-squares slope of the block's velocity along the incline over [t0, t_end], and the
// largest |F_slab + F_block| over the largest |F_block| of the logged contact forces.
struct Slide {
  Real acceleration = 0;
  Real speed_end = 0;
  Real worst_action_reaction = 0;
  Vec3 mean_pair_force = Vec3::Zero();  // logged force on the slab from the block over [t0, t_end]
  Real block_weight = 0;                // m g [N/m]
};

Slide RunIncline(Real theta_deg, const std::string& contact, Real t_end = 0.6, Real t0 = 0.1,
                 int dim = 2) {
  LoadedScene scene = LoadSceneFromString(
      dim == 2 ? InclineScene(theta_deg, contact) : InclineScene3D(theta_deg, contact),
      "block_on_slab.yaml");
  std::vector<Real> t, v;
  Slide out;
  Real largest = 0, imbalance = 0;  // max |F_block|, max |F_slab + F_block| [N/m]
  testing::RunUntil(scene, t_end, [&](const State& s, const StepReport& r) {
    const BodyMotion b = MotionOf(s.particles, 1);
    if (s.time >= t0) {
      t.push_back(s.time);
      v.push_back(b.momentum.x() / b.mass);
      if (!r.body_contact.pairs.empty()) out.mean_pair_force += r.body_contact.pairs[0].force;
    }
    out.block_weight = b.mass * kG;
    if (r.body_contact.force.size() == 2) {
      largest = std::max(largest, r.body_contact.force[1].norm());
      imbalance = std::max(imbalance, (r.body_contact.force[0] + r.body_contact.force[1]).norm());
    }
  });
  out.worst_action_reaction = largest > 0 ? imbalance / largest : 0;
  Real st = 0, sv = 0, stt = 0, stv = 0;
  const Real n = Real(t.size());
  for (size_t k = 0; k < t.size(); ++k) {
    st += t[k];
    sv += v[k];
    stt += t[k] * t[k];
    stv += t[k] * v[k];
  }
  out.acceleration = (n * stv - st * sv) / (n * stt - st * st);
  out.speed_end = v.empty() ? 0 : v.back();
  out.mean_pair_force /= Real(std::max<size_t>(t.size(), 1));
  return out;
}

TEST(BodyContactTest, BlockSlidesOnAnMpmSlabAtTheInclineAcceleration) {
  const Real theta = 25, mu = 0.3;
  const Slide s = RunIncline(theta, "body_contact:\n  - {bodies: [slab, block], friction: 0.3}\n");
  const Real th = theta * M_PI / 180;
  const Real expected = kG * (std::sin(th) - mu * std::cos(th));  // inclined plane, Coulomb
  std::printf("block on an MPM slab, theta %g deg, mu %g: a = %.4f m/s^2, closed form %.4f "
              "(error %+.2f %%); worst |F_slab + F_block| / |F_block| = %.2e\n",
              theta, mu, s.acceleration, expected, 100 * (s.acceleration / expected - 1),
              s.worst_action_reaction);
  EXPECT_NEAR(s.acceleration, expected, 0.03 * expected);
  EXPECT_LT(s.worst_action_reaction, 1e-9);  // two fields: action = reaction at every node
  // The logged force on the slab ("block_on_slab"): the block's weight component normal to the
  // incline (-y) and the friction mu times it, dragging the slab downhill (+x).
  const Real normal = s.block_weight * std::cos(th);
  std::printf("logged force on the slab: (%.2f, %.2f) N/m; expected (%.2f, %.2f)\n",
              s.mean_pair_force.x(), s.mean_pair_force.y(), mu * normal, -normal);
  EXPECT_NEAR(s.mean_pair_force.y(), -normal, 0.02 * normal);
  EXPECT_NEAR(s.mean_pair_force.x(), mu * normal, 0.03 * mu * normal);
}

TEST(BodyContactTest, BlockSlidesOnAnMpmSlabIn3D) {
  const Real theta = 25, mu = 0.3;
  const Slide s = RunIncline(theta, "body_contact:\n  - {bodies: [slab, block], friction: 0.3}\n",
                             0.5, 0.1, 3);
  const Real th = theta * M_PI / 180;
  const Real expected = kG * (std::sin(th) - mu * std::cos(th));
  const Real normal = s.block_weight * std::cos(th);
  std::printf("3-D block on an MPM slab: a = %.4f m/s^2, closed form %.4f (error %+.2f %%); "
              "logged force on the slab (%.2f, %.2f) N, expected (%.2f, %.2f)\n",
              s.acceleration, expected, 100 * (s.acceleration / expected - 1),
              s.mean_pair_force.x(), s.mean_pair_force.y(), mu * normal, -normal);
  EXPECT_NEAR(s.acceleration, expected, 0.03 * expected);
  EXPECT_NEAR(s.mean_pair_force.y(), -normal, 0.02 * normal);
  EXPECT_LT(s.worst_action_reaction, 1e-9);
}

TEST(BodyContactTest, WithoutBodyContactTheBlockIsWeldedToTheSlab) {
  const Slide s = RunIncline(25, "");
  const Real th = 25 * M_PI / 180;
  const Real expected = kG * (std::sin(th) - 0.3 * std::cos(th));
  std::printf("single velocity field: a = %.4f m/s^2 (sliding would be %.4f)\n", s.acceleration,
              expected);
  EXPECT_LT(std::abs(s.acceleration), 0.1 * expected);
}

TEST(BodyContactTest, BlockSticksWhenTheInclineIsBelowTheFrictionAngle) {
  const Real theta = 10;  // tan 10 deg = 0.18 < mu = 0.3
  const Slide s = RunIncline(theta, "body_contact:\n  - {bodies: [slab, block], friction: 0.3}\n");
  const Real free_slide = kG * std::sin(theta * M_PI / 180) * 0.6;  // frictionless speed at 0.6 s
  std::printf("block on an MPM slab, theta %g deg, mu 0.3: speed %.2e m/s at 0.6 s (frictionless "
              "%.3f m/s)\n", theta, s.speed_end, free_slide);
  EXPECT_LT(std::abs(s.speed_end), 0.01 * free_slide);
}

// Quasi-static initialisation with body contacts (Anura3D §6.3-6.5; docs/antilocking.md): the
// block released 0.15 m above the slab (theta = 0, separable frictional contact) falls and rings
// undamped; with local damping released at equilibrium (6.29)-(6.30) it lands and settles, and
// then, undamped, the logged contact force on the slab carries the block's weight and the block
// stays at rest. With mass scaling (beta = 4 while damped) it settles to the same state in fewer
// steps.
struct Settled {
  Real released = -1;        // time of the release [s]
  Real force_ratio_end = 0;  // logged force on the slab / block weight, mean over the last 0.1 s
  Real max_speed_after = 0;  // largest block speed after the release [m/s]
  Real max_speed_late = 0;   // largest block speed after t = 1.1 s [m/s]
  Real bottom = 0;           // the block's lowest particle - half a spacing at the end [m]
  long steps = 0;
};

Settled SettleBlock(const std::string& label, const std::string& extra,
                    const std::string& pair = "friction: 0.3") {
  std::string text = InclineScene(0, "body_contact:\n  - {bodies: [slab, block], " + pair + "}\n" + extra);
  text.replace(text.find("end: 1.0"), 8, "end: 1.5");
  const std::string region = "max: [0.55, 0.45]";
  text.replace(text.find("min: [0.3, 0.2], " + region), 17 + region.size(),
               "min: [0.3, 0.35], max: [0.55, 0.6]");  // 0.15 m (3 cells) above the slab
  LoadedScene scene = LoadSceneFromString(text, "settle_block.yaml");
  Settled out;
  Real force = 0, weight = 0;
  int samples = 0;
  testing::RunUntil(scene, 1.5, [&](const State& s, const StepReport& r) {
    ++out.steps;
    if (r.damping_released) out.released = s.time;
    const BodyMotion b = MotionOf(s.particles, 1);
    weight = b.mass * kG;
    const Real speed = b.momentum.norm() / b.mass;
    if (out.released > 0) out.max_speed_after = std::max(out.max_speed_after, speed);
    if (s.time > 1.1) out.max_speed_late = std::max(out.max_speed_late, speed);
    if (s.time > 1.4 && !r.body_contact.pairs.empty()) {
      force += -r.body_contact.pairs[0].force.y();  // the block pushes the slab down
      ++samples;
    }
  });
  out.force_ratio_end = force / samples / weight;
  out.bottom = 1e30;
  for (size_t p = 0; p < scene.state.particles.size(); ++p) {
    if (scene.state.particles.body[p] == 1) {
      out.bottom = std::min(out.bottom, scene.state.particles.x[p].y() - 0.5 * 0.05 / 2);
    }
  }
  std::printf("block dropped on an MPM slab, %s: released at %.4f s, contact force / weight "
              "%.5f over 1.4-1.5 s, max block speed after the release %.2e m/s and after 1.1 s %.2e m/s, "
              "block bottom at %.4f m (slab top 0.2 m), %ld steps\n",
              label.c_str(), out.released, out.force_ratio_end, out.max_speed_after,
              out.max_speed_late, out.bottom, out.steps);
  return out;
}

TEST(BodyContactTest, DampingAndMassScalingSettleABlockOnAnMpmSlab) {
  const Settled damped = SettleBlock("damped to equilibrium", "damping: {local: 0.7, equilibrium: {}}\n");
  EXPECT_GT(damped.released, 0);
  EXPECT_LT(damped.released, 1.2);
  EXPECT_NEAR(damped.force_ratio_end, 1.0, 0.01);
  EXPECT_LT(damped.max_speed_after, 1e-3);
  const Settled scaled = SettleBlock(
      "damped and mass-scaled to 1 s", "damping: {local: 0.7, until: 1.0}\nmass_scaling: {factor: 4, until: 1.0}\n");
  EXPECT_NEAR(scaled.force_ratio_end, 1.0, 0.01);
  EXPECT_LT(scaled.steps, 0.7 * damped.steps);  // sqrt(4) = 2x fewer steps over the scaled phase
  const Settled plain = SettleBlock("undamped", "");
  EXPECT_GT(plain.max_speed_late, 10 * damped.max_speed_late) << "undamped, the block still rings";
}

// The gap test between MPM bodies (BodyContact::gap_test, default for separable pairs): the block
// dropped 0.15 m comes to rest on the slab's surface (its lowest particle half a spacing above
// it). Without the test the fields meet as soon as their kernels share a node and the block
// stops in mid-air, about two cells up (the problem the test fixes).
TEST(BodyContactTest, GapTestLetsADroppedBlockLandOnTheSlab) {
  const std::string damping = "damping: {local: 0.7, until: 1.0}\n";
  const Settled gap = SettleBlock("gap test", damping);
  const Settled none = SettleBlock("no gap test", damping, "friction: 0.3, gap_test: false");
  const Real h = 0.05, r = h / 4;
  EXPECT_NEAR(gap.bottom, 0.2, 0.25 * r);
  EXPECT_GT(none.bottom, 0.2 + h);
  EXPECT_NEAR(gap.force_ratio_end, 1.0, 0.01);
  EXPECT_NEAR(none.force_ratio_end, 1.0, 0.01);
}

// Two elastic disks (Sulsky et al. 1994 §5, scenes/two_disks_2d.yaml) meeting head-on with
// frictionless separable contact: total momentum is conserved to round-off and they rebound.
TEST(BodyContactTest, DisksCollideAndSeparateConservingMomentum) {
  const std::string text = R"(name: two_disks_contact
dimension: 2
time: {end: 3.0, cfl: 0.4}
grid: {cell_size: 0.025, shape_function: quadratic_bspline, transfer: flip, update: usl}
domain: {min: [-0.5, -0.5], max: [1.5, 1.5]}
materials:
  elastic: {model: neo_hookean, density: 1000, youngs_modulus: 1000, poisson_ratio: 0.3}
bodies:
  - {name: lower_left, material: elastic, region: {sphere: {center: [0.25, 0.25], radius: 0.2}},
     particles_per_cell: 2, velocity: [0.1, 0.1]}
  - {name: upper_right, material: elastic, region: {sphere: {center: [0.75, 0.75], radius: 0.2}},
     particles_per_cell: 2, velocity: [-0.1, -0.1]}
body_contact:
  - {bodies: [lower_left, upper_right], friction: 0}
)";
  LoadedScene scene = LoadSceneFromString(text, "two_disks_contact.yaml");
  const BodyMotion a0 = MotionOf(scene.state.particles, 0), b0 = MotionOf(scene.state.particles, 1);
  const Real p0 = a0.momentum.norm();
  Real worst_drift = 0, min_gap = 1e30;
  int64_t contact_steps = 0;
  testing::RunUntil(scene, 3.0, [&](const State& s, const StepReport& r) {
    const BodyMotion a = MotionOf(s.particles, 0), b = MotionOf(s.particles, 1);
    worst_drift = std::max(worst_drift, (a.momentum + b.momentum).norm() / p0);
    min_gap = std::min(min_gap, (b.centre - a.centre).norm() - 0.4);
    contact_steps += r.body_contact.contact_nodes > 0;
  });
  const BodyMotion a = MotionOf(scene.state.particles, 0), b = MotionOf(scene.state.particles, 1);
  const Real ratio = -a.momentum.dot(a0.momentum) / (p0 * p0);  // rebound speed / approach speed
  std::printf("two disks with body contact: momentum drift %.2e, closest centre gap %.4f m, "
              "rebound speed ratio %.3f, %lld steps with contact nodes\n",
              worst_drift, min_gap, ratio, static_cast<long long>(contact_steps));
  EXPECT_LT(worst_drift, 1e-10);
  EXPECT_GT(contact_steps, 0);
  EXPECT_GT(ratio, 0.8);  // rebounds (an elastic collision gives 1)
  EXPECT_LT(b.momentum.dot(b0.momentum), 0);
}

}  // namespace
}  // namespace surge

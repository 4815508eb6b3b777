// RigidWorld (src/rigid/rigid_world.h): Bullet kinematics against closed forms, contact momentum,
// state round trip, determinism and mass properties.
#include "rigid/rigid_world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace surge {
namespace {

constexpr Real kEps = std::numeric_limits<Real>::epsilon();
constexpr Real kPi = std::numbers::pi_v<Real>;

bool BitwiseEqual(const RigidWorld::BodyState& a, const RigidWorld::BodyState& b) {
  return std::memcmp(a.position.data(), b.position.data(), sizeof(Vec3)) == 0 &&
         std::memcmp(a.rotation.data(), b.rotation.data(), sizeof(Mat3)) == 0 &&
         std::memcmp(a.velocity.data(), b.velocity.data(), sizeof(Vec3)) == 0 &&
         std::memcmp(a.angular_velocity.data(), b.angular_velocity.data(), sizeof(Vec3)) == 0;
}

Mat3 Rotation(Real angle, const Vec3& axis) {
  return Eigen::AngleAxis<Real>(angle, axis.normalized()).toRotationMatrix();
}

RigidBodyDesc Box(const Vec3& half, Real density, const Vec3& position) {
  RigidBodyDesc d;
  d.name = "box";
  d.shape = RigidBox{half};
  d.density = density;
  d.position = position;
  return d;
}

// Bullet integrates semi-implicit (symplectic) Euler: v_{k+1} = v_k + g dt, x_{k+1} = x_k +
// v_{k+1} dt, so after N steps x_N = x0 + v0 t + g dt^2 N (N + 1) / 2 = x0 + v0 t + g t^2 / 2 +
// g t dt / 2 (t = N dt). The state must match this discrete solution to round-off, and the exact
// parabola within the O(dt) term g t dt / 2.
TEST(RigidWorldTest, FreeFallFollowsTheParabola) {
  const Vec3 g(0, -9.81, 0);
  RigidWorld world(g);
  RigidBodyDesc d;
  d.shape = RigidSphere{0.3};
  d.mass = 2;
  d.position = Vec3(1, 5, -2);
  d.velocity = Vec3(1.5, 2, -0.5);
  const int body = world.AddBody(d);
  const Real dt = 1e-3;
  const int n = 1000;
  for (int k = 0; k < n; ++k) world.Step(dt);
  const Real t = n * dt;
  const RigidWorld::BodyState s = world.State(body);
  const Vec3 discrete = d.position + d.velocity * t + g * (dt * dt * n * (n + 1) / 2);
  const Vec3 parabola = d.position + d.velocity * t + g * (t * t / 2);
  const Real roundoff = 4 * n * kEps * 10;  // n additions of O(10 m) values
  EXPECT_LT((s.position - discrete).norm(), roundoff);
  EXPECT_LT((s.velocity - (d.velocity + g * t)).norm(), 4 * n * kEps * 10);
  EXPECT_LT((s.position - parabola).norm(), g.norm() * t * dt / 2 + roundoff);
  EXPECT_GT((s.position - parabola).norm(), g.norm() * t * dt / 2 - roundoff);  // the O(dt) term
  EXPECT_EQ(s.angular_velocity, Vec3::Zero());
}

// A box resting on the ground plane stays put: y = h within 1e-4 m over 1 s at dt = 1e-3.
TEST(RigidWorldTest, BoxRestsOnGround) {
  RigidWorld world(Vec3(0, -9.81, 0), GroundPlane{Vec3::Zero(), Vec3::UnitY(), 0.6});
  const Vec3 half(0.5, 0.25, 0.4);
  const Vec3 start(0.3, half.y(), -0.2);
  const int body = world.AddBody(Box(half, 2500, start));
  Real max_drift = 0;
  for (int k = 0; k < 1000; ++k) {
    world.Step(1e-3);
    max_drift = std::max(max_drift, (world.State(body).position - start).norm());
  }
  const RigidWorld::BodyState s = world.State(body);
  EXPECT_LT(max_drift, 1e-4);
  EXPECT_LT(s.velocity.norm(), 1e-3);
  EXPECT_LT((s.rotation - Mat3::Identity()).norm(), 1e-4);
}

// Newton: a constant force F on a free body gives a = F / m; the force lasts one Step only.
TEST(RigidWorldTest, ConstantForceGivesFOverM) {
  RigidWorld world(Vec3::Zero());
  RigidBodyDesc d = Box(Vec3(0.2, 0.3, 0.4), 0, Vec3(0, 1, 0));
  d.mass = 3;
  const int body = world.AddBody(d);
  const Vec3 force(6, -3, 1.5);
  const Real dt = 1e-3;
  const int n = 200;
  for (int k = 0; k < n; ++k) {
    world.ApplyForce(body, force, Vec3::Zero());
    world.Step(dt);
  }
  const Vec3 expected = force / d.mass * (n * dt);
  EXPECT_LT((world.State(body).velocity - expected).norm(), 4 * n * kEps * expected.norm());
  EXPECT_LT(world.State(body).angular_velocity.norm(), 4 * n * kEps);
  world.Step(dt);  // no ApplyForce: velocity unchanged
  EXPECT_LT((world.State(body).velocity - expected).norm(), 4 * n * kEps * expected.norm());
}

// Euler: a constant torque about a principal axis gives alpha = T / I about it (omega x I omega
// vanishes for omega along a principal axis). The body is rotated so the axis is not a world axis.
TEST(RigidWorldTest, ConstantTorqueAboutPrincipalAxisGivesTOverI) {
  RigidWorld world(Vec3::Zero());
  RigidBodyDesc d = Box(Vec3(0.3, 0.5, 0.7), 1000, Vec3::Zero());
  d.rotation = Rotation(0.4, Vec3(1, 2, 3));
  const int body = world.AddBody(d);
  const Vec3 axis = d.rotation.col(0);  // body x, principal
  const Real i_x = world.PrincipalInertia(body).x();
  const Real torque = 2.5;
  const Real dt = 1e-3;
  const int n = 500;
  for (int k = 0; k < n; ++k) {
    world.ApplyForce(body, Vec3::Zero(), torque * axis);
    world.Step(dt);
  }
  const Vec3 omega = world.State(body).angular_velocity;
  const Vec3 expected = torque / i_x * (n * dt) * axis;
  EXPECT_LT((omega - expected).norm(), 1e-10 * expected.norm());
  // The body turned about that axis by sum_k alpha k dt^2 = alpha dt^2 n (n + 1) / 2.
  const Mat3 turned = world.State(body).rotation * d.rotation.transpose();
  const Real angle = Eigen::AngleAxis<Real>(turned).angle();
  EXPECT_NEAR(angle, torque / i_x * dt * dt * n * (n + 1) / 2, 1e-10);
  EXPECT_LT(world.State(body).velocity.norm(), 1e-14);
}

// Two boxes collide head-on without gravity: linear momentum before = after (the contact impulses
// are equal and opposite), and the struck box moves off.
TEST(RigidWorldTest, CollisionConservesMomentum) {
  RigidWorld world(Vec3::Zero());
  RigidBodyDesc a = Box(Vec3::Constant(0.25), 0, Vec3(-1, 0, 0));
  a.mass = 2;
  a.velocity = Vec3(3, 0, 0);
  a.restitution = 0.5;
  RigidBodyDesc b = Box(Vec3::Constant(0.25), 0, Vec3(0.2, 0.05, 0));
  b.mass = 5;
  b.restitution = 0.5;
  const int ia = world.AddBody(a);
  const int ib = world.AddBody(b);
  const Vec3 p0 = a.mass * a.velocity + b.mass * b.velocity;
  for (int k = 0; k < 1000; ++k) world.Step(1e-3);
  const Vec3 va = world.State(ia).velocity, vb = world.State(ib).velocity;
  const Vec3 p1 = a.mass * va + b.mass * vb;
  EXPECT_LT((p1 - p0).norm(), 1e-4 * p0.norm());
  EXPECT_GT(vb.x(), 0.5);     // it was hit
  EXPECT_LT(va.x(), vb.x());  // and they separate
}

TEST(RigidWorldTest, SetStateRoundTripsExactly) {
  RigidWorld world(Vec3(0, -9.81, 0), GroundPlane{});
  const int box = world.AddBody(Box(Vec3(0.2, 0.3, 0.4), 1200, Vec3(0, 2, 0)));
  RigidBodyDesc hull;
  hull.shape = RigidConvexHull{
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1.3, 0), Vec3(0, 0, 0.7), Vec3(0.6, 0.6, 0.6)}};
  hull.density = 2600;
  hull.position = Vec3(3, 3, 0);
  const int rock = world.AddBody(hull);
  RigidWorld::BodyState s;
  s.position = Vec3(0.1 / 3, 1 / 7.0, std::sqrt(2.0));
  s.rotation = Rotation(1 / 3.0, Vec3(0.3, -1, std::sqrt(5.0)));
  s.velocity = Vec3(-1 / 9.0, std::acos(0.3), 1e-17);
  s.angular_velocity = Vec3(std::exp(1.0), -1 / 11.0, 0.1);
  for (int body : {box, rock}) {
    world.SetState(body, s);
    EXPECT_TRUE(BitwiseEqual(world.State(body), s)) << body;
  }
  world.Step(1e-3);
  const RigidWorld::BodyState after = world.State(box);
  world.SetState(box, after);
  EXPECT_TRUE(BitwiseEqual(world.State(box), after));
}

// A checkpoint restored into a fresh world continues bitwise (tumbling body, no contact: Bullet's
// contact caches are not part of BodyState, see docs/rigid-bodies.md).
TEST(RigidWorldTest, RestoredWorldContinuesBitwiseInFreeFlight) {
  auto make = [](RigidWorld& w) {
    RigidBodyDesc d = Box(Vec3(0.2, 0.5, 0.9), 900, Vec3(0, 10, 0));
    d.velocity = Vec3(1, 2, 0);
    d.angular_velocity = Vec3(3, 0.5, -1);  // not about a principal axis: gyroscopic terms act
    return w.AddBody(d);
  };
  auto push = [](RigidWorld& w, int body, int k) {
    w.ApplyForce(body, Vec3(std::sin(0.01 * k), 1, 0), Vec3(0, 0.1 * std::cos(0.02 * k), 0.2));
    w.Step(2e-4);
  };
  RigidWorld a(Vec3(0, -9.81, 0));
  const int ia = make(a);
  for (int k = 0; k < 300; ++k) push(a, ia, k);
  RigidWorld b(Vec3(0, -9.81, 0));
  const int ib = make(b);
  b.SetState(ib, a.State(ia));
  for (int k = 300; k < 600; ++k) {
    push(a, ia, k);
    push(b, ib, k);
  }
  EXPECT_TRUE(BitwiseEqual(a.State(ia), b.State(ib)));
  EXPECT_GT((a.State(ia).angular_velocity - Vec3(3, 0.5, -1)).norm(), 1e-3);  // it did tumble
}

// A box, a sphere, a tilted cylinder and a spinning hull (angular velocity `hull_spin`) above
// one another: they fall on the ground and on each other.
void AddPile(RigidWorld& w, const Vec3& hull_spin) {
  w.AddBody(Box(Vec3(0.5, 0.2, 0.5), 2000, Vec3(0, 0.2, 0)));
  RigidBodyDesc s;
  s.shape = RigidSphere{0.3};
  s.density = 2500;
  s.position = Vec3(0.1, 1.0, 0.05);
  w.AddBody(s);
  RigidBodyDesc c;
  c.shape = RigidCylinder{0.2, 0.4};
  c.density = 1500;
  c.position = Vec3(-0.3, 2.0, 0.2);
  c.rotation = Rotation(0.7, Vec3(1, 0, 1));
  w.AddBody(c);
  RigidBodyDesc h;
  h.shape = RigidConvexHull{{Vec3(-0.3, -0.2, -0.1), Vec3(0.4, -0.2, 0), Vec3(0, 0.3, -0.2),
                             Vec3(0.1, 0, 0.4), Vec3(-0.2, 0.2, 0.3)}};
  h.density = 2700;
  h.position = Vec3(0.2, 3.0, -0.1);
  h.angular_velocity = hull_spin;
  w.AddBody(h);
}

// Same calls in the same order -> bitwise the same states, with contacts (boxes, a sphere, a hull
// and a cylinder falling on the ground and on each other).
TEST(RigidWorldTest, IdenticalWorldsStayBitwiseEqual) {
  auto build = [](RigidWorld& w) { AddPile(w, Vec3(1, 2, 3)); };
  RigidWorld a(Vec3(0, -9.81, 0), GroundPlane{Vec3::Zero(), Vec3(0.1, 1, 0), 0.5});
  RigidWorld b(Vec3(0, -9.81, 0), GroundPlane{Vec3::Zero(), Vec3(0.1, 1, 0), 0.5});
  build(a);
  build(b);
  for (int k = 0; k < 1000; ++k) {
    for (RigidWorld* w : {&a, &b}) {
      w->ApplyForce(0, Vec3(5 * std::sin(0.01 * k), 0, 0), Vec3(0, 0.3, 0));
      w->Step(1e-3);
    }
  }
  for (int body = 0; body < a.BodyCount(); ++body)
    EXPECT_TRUE(BitwiseEqual(a.State(body), b.State(body))) << body;
  EXPECT_LT(a.State(3).position.y(), 2.0);  // the hull fell: contacts were exercised
}

// A world rebuilt from a checkpoint during contacts (four bodies piling up on a tilted ground):
// the body states plus ContactCache continue bitwise; the states alone do not (Bullet's
// persistent contact points and their warm-start impulses are history).
TEST(RigidWorldTest, RestoredWorldContinuesBitwiseDuringContacts) {
  auto build = [](RigidWorld& w) { AddPile(w, Vec3::Zero()); };
  const GroundPlane ground{Vec3::Zero(), Vec3(0.1, 1, 0), 0.5};
  auto step = [](RigidWorld& w, int k) {
    w.ApplyForce(0, Vec3(5 * std::sin(0.01 * k), 0, 0), Vec3(0, 0.3, 0));
    w.Step(1e-3);
  };
  RigidWorld a(Vec3(0, -9.81, 0), ground);
  build(a);
  for (int k = 0; k < 1500; ++k) step(a, k);  // everything has landed: contacts persist
  std::vector<RigidWorld::BodyState> states;
  for (int body = 0; body < a.BodyCount(); ++body) states.push_back(a.State(body));
  const std::vector<uint8_t> cache = a.ContactCache();
  ASSERT_GT(cache.size(), 8u);
  RigidWorld b(Vec3(0, -9.81, 0), ground), c(Vec3(0, -9.81, 0), ground);
  build(b);
  build(c);
  for (int body = 0; body < a.BodyCount(); ++body) {
    b.SetState(body, states[size_t(body)]);
    c.SetState(body, states[size_t(body)]);
  }
  EXPECT_EQ(b.RestoreContactCache(cache), 0);
  for (int k = 1500; k < 2000; ++k) {
    for (RigidWorld* w : {&a, &b, &c}) step(*w, k);
  }
  bool c_differs = false;
  for (int body = 0; body < a.BodyCount(); ++body) {
    EXPECT_TRUE(BitwiseEqual(a.State(body), b.State(body))) << body;
    c_differs = c_differs || !BitwiseEqual(a.State(body), c.State(body));
  }
  EXPECT_TRUE(c_differs) << "without the contact cache the restart should differ";
  EXPECT_THROW(b.RestoreContactCache(std::vector<uint8_t>(3, 0)), std::exception);
}

// Mass and inertia from density against closed forms (solid cuboid, sphere, cylinder:
// e.g. Goldstein, Classical Mechanics, 3rd ed., or any engineering table).
TEST(RigidWorldTest, MassPropertiesMatchClosedForms) {
  RigidWorld world(Vec3::Zero());
  const Real rho = 2400;
  const Real a = 0.3, b = 0.5, c = 0.7;  // half extents
  const int box = world.AddBody(Box(Vec3(a, b, c), rho, Vec3::Zero()));
  const Real m_box = rho * 2 * a * 2 * b * 2 * c;
  EXPECT_NEAR(world.Mass(box), m_box, 4 * kEps * m_box);
  const Vec3 i_box =
      m_box / 12 * Vec3(4 * b * b + 4 * c * c, 4 * a * a + 4 * c * c, 4 * a * a + 4 * b * b);
  EXPECT_LT((world.PrincipalInertia(box) - i_box).norm(), 8 * kEps * i_box.norm());

  RigidBodyDesc sphere;
  sphere.shape = RigidSphere{0.4};
  sphere.density = rho;
  sphere.position = Vec3(3, 0, 0);
  const int ball = world.AddBody(sphere);
  const Real m_ball = rho * 4.0 / 3.0 * kPi * 0.4 * 0.4 * 0.4;
  EXPECT_NEAR(world.Mass(ball), m_ball, 4 * kEps * m_ball);
  EXPECT_LT((world.PrincipalInertia(ball) - Vec3::Constant(0.4 * m_ball * 0.16)).norm(),
            8 * kEps * m_ball);

  RigidBodyDesc cyl;
  cyl.shape = RigidCylinder{0.25, 0.6};
  cyl.density = rho;
  cyl.position = Vec3(-3, 0, 0);
  cyl.rotation = Rotation(kPi / 2, Vec3::UnitZ());  // axis along world -x
  const int drum = world.AddBody(cyl);
  const Real len = 1.2, r = 0.25;
  const Real m_drum = rho * kPi * r * r * len;
  EXPECT_NEAR(world.Mass(drum), m_drum, 4 * kEps * m_drum);
  const Real side = m_drum * (3 * r * r + len * len) / 12, axial = m_drum * r * r / 2;
  EXPECT_LT((world.PrincipalInertia(drum) - Vec3(side, axial, side)).norm(), 8 * kEps * side);
  const Mat3 expected_world = Vec3(axial, side, side).asDiagonal();
  EXPECT_LT((world.InertiaWorld(drum) - expected_world).norm(), 1e-12 * side);

  RigidBodyDesc heavy = Box(Vec3::Constant(0.1), 0, Vec3(0, 5, 0));
  heavy.mass = 7.5;
  const int block = world.AddBody(heavy);
  EXPECT_EQ(world.Mass(block), 7.5);
  EXPECT_LT((world.PrincipalInertia(block) - Vec3::Constant(7.5 * 0.04 / 12 * 2)).norm(), 1e-15);
}

// Convex hull mass properties (tetrahedra) against the closed forms: the hull of a box's corners,
// rotated and shifted, is that box; a unit right tetrahedron has V = 1/6, centroid (1/4, 1/4, 1/4).
TEST(RigidWorldTest, HullMassPropertiesMatchClosedForms) {
  const Vec3 half(0.3, 0.5, 0.7);
  const Mat3 q = Rotation(0.9, Vec3(1, -2, 0.5));
  const Vec3 shift(0.4, -0.2, 1.1);
  RigidConvexHull corners;
  for (int i = 0; i < 8; ++i) {
    const Vec3 sign((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    corners.points.push_back(shift + q * half.cwiseProduct(sign));
  }
  corners.points.push_back(shift);  // an interior point changes nothing
  const ShapeMassProperties p = ComputeShapeMassProperties(corners);
  const ShapeMassProperties box = ComputeShapeMassProperties(RigidBox{half});
  EXPECT_NEAR(p.volume, box.volume, 1e-14);
  EXPECT_LT((p.centroid - shift).norm(), 1e-14);
  const Mat3 expected = q * box.inertia_per_density * q.transpose();
  EXPECT_LT((p.inertia_per_density - expected).norm(), 1e-14);

  const ShapeMassProperties tet = ComputeShapeMassProperties(
      RigidConvexHull{{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()}});
  EXPECT_NEAR(tet.volume, 1.0 / 6, 1e-15);
  EXPECT_LT((tet.centroid - Vec3::Constant(0.25)).norm(), 1e-15);
  // About the origin int (y^2 + z^2) dV = 1/30 and int x y dV = 1/120 (Tonon 2004); the parallel
  // axis shift by V c c^T (V = 1/6, c = 1/4) gives I_xx = 1/30 - 1/48 and I_xy = -(1/120 - 1/96).
  EXPECT_NEAR(tet.inertia_per_density(0, 0), 1.0 / 30 - 1.0 / 48, 1e-15);
  EXPECT_NEAR(tet.inertia_per_density(0, 1), -(1.0 / 120 - 1.0 / 96), 1e-15);

  // As a body: the centre of mass goes to the centroid, inertia to principal axes.
  RigidWorld world(Vec3::Zero());
  RigidBodyDesc d;
  d.shape = corners;
  d.density = 1000;
  d.position = Vec3(1, 2, 3);
  const int body = world.AddBody(d);
  EXPECT_LT((world.State(body).position - (d.position + shift)).norm(), 1e-14);
  EXPECT_LT((world.InertiaWorld(body) - 1000 * expected).norm(), 1e-12 * expected.norm() * 1000);
  EXPECT_NEAR(world.Mass(body), 1000 * box.volume, 1e-11);
}

// A sphere dropped on a static triangle-mesh floor comes to rest on it (y = r).
TEST(RigidWorldTest, SphereLandsOnStaticMesh) {
  RigidWorld world(Vec3(0, -9.81, 0));
  RigidBodyDesc floor;
  floor.name = "floor";
  floor.shape = RigidTriangleMesh{{Vec3(-2, 0, -2), Vec3(2, 0, -2), Vec3(2, 0, 2), Vec3(-2, 0, 2)},
                                  {{0, 2, 1}, {0, 3, 2}}};
  const int ground = world.AddBody(floor);
  RigidBodyDesc ball;
  ball.shape = RigidSphere{0.25};
  ball.density = 1000;
  ball.position = Vec3(0.3, 1, 0.1);
  const int body = world.AddBody(ball);
  for (int k = 0; k < 2000; ++k) world.Step(1e-3);
  EXPECT_NEAR(world.State(body).position.y(), 0.25, 1e-3);
  EXPECT_LT(world.State(body).velocity.norm(), 1e-2);
  EXPECT_EQ(world.Mass(ground), 0);
  EXPECT_EQ(world.Name(ground), "floor");
}

TEST(RigidWorldTest, RejectsBadDescriptions) {
  RigidWorld world(Vec3::Zero());
  RigidBodyDesc both = Box(Vec3::Constant(0.1), 1000, Vec3::Zero());
  both.mass = 1;
  EXPECT_THROW(world.AddBody(both), std::invalid_argument);
  RigidBodyDesc mesh;
  mesh.shape = RigidTriangleMesh{{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()}, {{0, 1, 2}}};
  mesh.mass = 1;
  EXPECT_THROW(world.AddBody(mesh), std::invalid_argument);
  RigidBodyDesc flat;
  flat.shape = RigidConvexHull{{Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), Vec3(1, 1, 0)}};
  flat.density = 1000;
  EXPECT_THROW(world.AddBody(flat), std::invalid_argument);
  RigidBodyDesc skew = Box(Vec3::Constant(0.1), 1000, Vec3::Zero());
  skew.rotation(0, 1) = 0.1;
  EXPECT_THROW(world.AddBody(skew), std::invalid_argument);
  EXPECT_EQ(world.BodyCount(), 0);
}

}  // namespace
}  // namespace surge

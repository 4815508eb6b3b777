// Two-way coupling of dynamic obstacles with Bullet (issue #5; DESIGN §4 step 6; docs/rigid-
// bodies.md): the node contact used each body's state at t_n (State::rigid); its reaction on the
// body, the force m (v_u - v_c) / dt summed over the body's nodes and moved particles, and its
// moment about the centre of mass act with the ramped weight for one step dt; Bullet advances
// the body (stepSimulation(dt, 0): no substeps), colliding with the other dynamic bodies, the
// fixed obstacles and the domain walls, and State::rigid takes the result for the next step.
#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <variant>

#include "contact/mesh_distance.h"
#include "core/log.h"
#include "step/stages.h"

namespace surge {
namespace {

// Rotation taking the y axis onto unit vector a (Bullet cylinders are along their y axis).
Mat3 AlignY(const Vec3& a) {
  return Eigen::Quaternion<Real>::FromTwoVectors(Vec3::UnitY(), a).toRotationMatrix();
}

// Bullet shape and placement of an obstacle shape (reference pose). Polygons become the convex
// hull of their extrusion, meshes the convex hull of their vertices when dynamic and the exact
// triangles when static (Bullet has no dynamic concave meshes).
RigidBodyDesc Describe(const Obstacle& o, int dim, bool dynamic) {
  RigidBodyDesc d;
  d.name = o.name;
  d.friction = o.contact.friction;
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, BoxShape>) {
          d.shape = RigidBox{0.5 * (s.max - s.min)};
          d.position = 0.5 * (s.min + s.max);
        } else if constexpr (std::is_same_v<S, SphereShape>) {
          d.shape = RigidSphere{s.radius};
          d.position = s.center;
        } else if constexpr (std::is_same_v<S, CylinderShape>) {
          d.shape = RigidCylinder{s.radius, 0.5 * (s.top - s.base).norm()};
          d.position = 0.5 * (s.base + s.top);
          d.rotation = AlignY((s.top - s.base).normalized());
        } else if constexpr (std::is_same_v<S, PlaneShape>) {
          // A static slab 1 km wide and 10 m thick under the plane.
          d.shape = RigidBox{Vec3(500, 5, 500)};
          d.rotation = AlignY(s.normal);
          d.position = s.point - 5 * s.normal;
        } else if constexpr (std::is_same_v<S, PolygonShape>) {
          RigidConvexHull hull;
          const Real z0 = dim == 3 ? s.z0 : -0.5, z1 = dim == 3 ? s.z1 : 0.5;
          for (const auto& q : s.points) {
            hull.points.emplace_back(q[0], q[1], z0);
            hull.points.emplace_back(q[0], q[1], z1);
          }
          d.shape = hull;
        } else {
          const TriangleMesh& mesh = s.field->mesh();
          if (dynamic) {
            d.shape = RigidConvexHull{mesh.vertices};
          } else {
            d.shape = RigidTriangleMesh{mesh.vertices, mesh.triangles};
          }
        }
      },
      o.shape);
  if (dynamic) {
    d.mass = o.motion.mass;
    d.density = o.motion.density;
    d.restitution = o.motion.restitution;
  }
  return d;
}

void BuildRigidWorld(const Model& m, const State& s, Workspace& w) {
  w.rigid_world = std::make_unique<RigidWorld>(Vec3::Zero());  // weight applied as a force
  RigidWorld& world = *w.rigid_world;
  // Domain walls: static slabs 10 m thick outside each walled face; friction as the wall's.
  const Vec3 size = m.domain_max - m.domain_min;
  const Vec3 center = 0.5 * (m.domain_min + m.domain_max);
  for (int f = 0; f < 2 * m.dim; ++f) {
    const Wall& wall = m.walls[f];
    if (wall.kind == WallKind::kOpen) continue;
    const int a = f / 2;
    const Real sign = f % 2 == 0 ? -1 : 1;
    RigidBodyDesc d;
    d.name = std::string("domain ") + FaceName(Face(f));
    Vec3 half = 0.5 * size + Vec3::Constant(10.0);
    half[a] = 5;
    d.shape = RigidBox{half};
    d.position = center;
    d.position[a] = (sign < 0 ? m.domain_min[a] : m.domain_max[a]) + sign * 5;
    d.friction = wall.kind == WallKind::kFriction ? wall.friction
                 : wall.kind == WallKind::kNoSlip ? 1.0
                                                  : 0.0;
    world.AddBody(d);
  }
  for (const Obstacle& o : m.obstacles) {
    if (o.motion.kind == ObstacleMotionKind::kFixed) world.AddBody(Describe(o, m.dim, false));
  }
  // Prescribed obstacles are not in the Bullet world (Bullet would need kinematic bodies).
  const size_t n = s.rigid.size();
  w.rigid_handle.assign(n, -1);
  w.rigid_frame0.assign(n, Mat3::Identity());
  w.rigid_offset.assign(n, Vec3::Zero());
  w.rigid_mass.assign(n, 0);
  for (const Obstacle& o : m.obstacles) {
    if (o.motion.kind != ObstacleMotionKind::kDynamic) continue;
    const size_t k = size_t(o.motion.body);
    const int h = world.AddBody(Describe(o, m.dim, true));
    const RigidWorld::BodyState b0 = world.State(h);  // Bullet's frame at the reference pose
    w.rigid_handle[k] = h;
    w.rigid_frame0[k] = b0.rotation;
    w.rigid_offset[k] = b0.rotation.transpose() * (o.motion.center - b0.position);
    w.rigid_mass[k] = world.Mass(h);
    // Start from the state of record (t = 0, or a restart): the reference point p at c(t).
    const RigidBodyState& r = s.rigid[k];
    RigidWorld::BodyState b;
    b.rotation = r.rotation * b0.rotation;
    b.position = r.position - b.rotation * w.rigid_offset[k];
    b.angular_velocity = r.angular_velocity;
    b.velocity = r.velocity - r.angular_velocity.cross(r.position - b.position);
    world.SetState(h, k < w.rigid_restart.size() ? w.rigid_restart[k] : b);
  }
  // A restart: the contact points Bullet carried from step to step (warm-start impulses).
  if (!w.rigid_restart_contacts.empty()) {
    const int missing = world.RestoreContactCache(w.rigid_restart_contacts);
    if (missing > 0) {
      LogWarn("restart: " + std::to_string(missing) +
              " rigid-body contact(s) of the checkpoint not restored (the bodies are out of "
              "contact range); the run continues");
    }
    w.rigid_restart_contacts.clear();
  }
}

}  // namespace

void RigidBodiesStage(const Model& m, const StepContext& c, State& s, Workspace& w,
                      StepReport& r) {
  if (!w.rigid_world) BuildRigidWorld(m, s, w);
  RigidWorld& world = *w.rigid_world;
  for (size_t o = 0; o < m.obstacles.size(); ++o) {
    const Obstacle& ob = m.obstacles[o];
    if (ob.motion.kind != ObstacleMotionKind::kDynamic) continue;
    const size_t k = size_t(ob.motion.body);
    const int h = w.rigid_handle[k];
    // The reaction is the force ON the structure, its torque taken about the reference point
    // p = State::rigid position; Bullet wants it about the centre of mass c_b: add (p - c_b) x F.
    const ObstacleForce& f = r.obstacles.at(o);
    const Vec3 com = world.State(h).position;
    const Vec3 torque = f.torque + (s.rigid[k].position - com).cross(f.force);
    world.ApplyForce(h, f.force + w.rigid_mass[k] * c.gravity, torque);
  }
  world.Step(c.dt);  // stepSimulation(dt, 0, dt)
  for (const Obstacle& ob : m.obstacles) {
    if (ob.motion.kind != ObstacleMotionKind::kDynamic) continue;
    const size_t k = size_t(ob.motion.body);
    const RigidWorld::BodyState b = world.State(w.rigid_handle[k]);
    const Vec3 p = b.position + b.rotation * w.rigid_offset[k];
    s.rigid[k] = RigidBodyState{p, b.rotation * w.rigid_frame0[k].transpose(),
                                b.velocity + b.angular_velocity.cross(p - b.position),
                                b.angular_velocity};
  }
}

}  // namespace surge

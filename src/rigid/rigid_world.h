// Rigid-body dynamics of movable obstacles (boulders, loose blocks; DESIGN §4 stage 6, issue #5):
// a Bullet world behind our own types. Bullet is included only by rigid_world.cpp (pimpl).
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/math.h"

namespace surge {

// Shapes are given in the body frame: origin at RigidBodyDesc::position, axes
// RigidBodyDesc::rotation.
struct RigidBox {
  Vec3 half_extents = Vec3::Constant(0.5);  // [m]
};
struct RigidSphere {
  Real radius = 0.5;  // [m]
};
struct RigidCylinder {     // axis along the body y axis, centred on the origin
  Real radius = 0.5;       // [m]
  Real half_height = 0.5;  // [m]
};
// Convex hull of the points (body frame). The centre of mass is the hull's centroid, which need not
// be the origin: State().position after AddBody is desc.position + desc.rotation * centroid.
struct RigidConvexHull {
  std::vector<Vec3> points;  // [m], at least 4, not coplanar
};
// Static only (mass = density = 0): terrain, fixed walls that bodies land on.
struct RigidTriangleMesh {
  std::vector<Vec3> vertices;                 // [m]
  std::vector<std::array<int, 3>> triangles;  // indices into vertices
};
using RigidShape =
    std::variant<RigidBox, RigidSphere, RigidCylinder, RigidConvexHull, RigidTriangleMesh>;

// One body. Give either `mass` or `density` (not both); both zero makes the body static.
// Inertia always comes from the shape with uniform density (closed forms, see rigid_world.cpp).
struct RigidBodyDesc {
  std::string name;
  RigidShape shape = RigidBox{};
  Real mass = 0;     // [kg]; 0 with density 0: static (infinite mass, never moves)
  Real density = 0;  // [kg/m^3]; > 0: mass = density * volume(shape)
  Vec3 position =
      Vec3::Zero();  // body-frame origin in the world [m] (= centre of mass except hulls)
  Mat3 rotation = Mat3::Identity();      // body frame -> world, proper rotation
  Vec3 velocity = Vec3::Zero();          // of the centre of mass [m/s]
  Vec3 angular_velocity = Vec3::Zero();  // world frame [rad/s]
  Real friction = 0.5;     // Coulomb coefficient; Bullet multiplies the two bodies' values
  Real restitution = 0.0;  // Bullet multiplies the two bodies' values
};

struct GroundPlane {            // static half-space below `point` along -normal
  Vec3 point = Vec3::Zero();    // [m]
  Vec3 normal = Vec3::UnitY();  // unit, pointing out of the ground
  Real friction = 0.5;
};

// Bullet world stepped once per MPM step. Coupling (docs/rigid-bodies.md): the contact's reaction
// on each body goes in through ApplyForce, Step(dt) advances Bullet by exactly dt with
// stepSimulation(dt, 0, dt) (no substeps, no interpolation), and State() gives the pose and
// velocities for the next contact.
//
// Precision: Bullet is built against its double-precision Debian libraries (*-float64,
// BT_USE_DOUBLE_PRECISION; btScalar = double), so Real values pass in and out unrounded and
// SetState/State round-trip exactly. Determinism: single-threaded Bullet, no randomised solver
// order; the same calls in the same order give bitwise identical states.
//
// Frames: State().rotation is the orientation of the body's principal frame. For boxes, spheres
// and cylinders that is desc.rotation; for a hull it is desc.rotation * (principal axes of the
// hull). Consumers that need the motion of the shape (the contact's ObstaclePose) should use the
// relative rotation State(t).rotation * State(0).rotation^T, which is frame-independent.
class RigidWorld {
 public:
  struct BodyState {
    Vec3 position = Vec3::Zero();          // centre of mass [m]
    Mat3 rotation = Mat3::Identity();      // principal frame -> world
    Vec3 velocity = Vec3::Zero();          // of the centre of mass [m/s]
    Vec3 angular_velocity = Vec3::Zero();  // world frame [rad/s]
  };

  explicit RigidWorld(const Vec3& gravity, const std::optional<GroundPlane>& ground = std::nullopt);
  ~RigidWorld();
  RigidWorld(const RigidWorld&) = delete;
  RigidWorld& operator=(const RigidWorld&) = delete;

  // Adds a body and returns its index (0, 1, ... in call order; the ground plane has none).
  // Throws std::invalid_argument on a bad description (negative sizes, mass and density both set,
  // dynamic triangle mesh, degenerate hull, non-orthonormal rotation).
  int AddBody(const RigidBodyDesc& desc);
  int BodyCount() const;
  const std::string& Name(int body) const;

  // Force [N] at the centre of mass and torque [N m] about it (world frame). Accumulated over
  // calls and used by the next Step only. No effect on static bodies.
  void ApplyForce(int body, const Vec3& force, const Vec3& torque_about_com);

  // Advances every body by exactly dt [s] (gravity + applied forces, contacts), then clears the
  // applied forces. Pre: dt > 0.
  void Step(Real dt);

  BodyState State(int body) const;
  // Sets pose and velocities (for checkpoints). State(b) afterwards returns `state` bitwise.
  // Contact caches (Bullet's persistent manifolds) are not part of BodyState: ContactCache.
  void SetState(int body, const BodyState& state);

  // Bullet's persistent contact manifolds (contact points with their warm-start impulses), as
  // bytes for a checkpoint. A world rebuilt with the same bodies, SetState to the same states
  // and then RestoreContactCache continues bitwise as this one would (the contacts are solved in
  // the order of their body indices, so no other history matters). The bytes are specific to
  // this build of Bullet (checked on restore).
  std::vector<uint8_t> ContactCache() const;
  // Pre: every body added and SetState. Returns how many saved manifolds found no pair in contact
  // range at the restored poses (0 when the states are those the cache was saved with).
  int RestoreContactCache(const std::vector<uint8_t>& cache);

  Real Mass(int body) const;              // [kg]; 0 for static bodies
  Vec3 PrincipalInertia(int body) const;  // body-frame diagonal [kg m^2]; zero for static
  Mat3 InertiaWorld(int body) const;      // R diag(I) R^T [kg m^2] about the centre of mass

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Volume [m^3], centroid [m] and inertia tensor per unit density [m^5] about the centroid, in the
// shape's own frame. Static meshes have no volume here (throws). Exposed for tests and builders.
struct ShapeMassProperties {
  Real volume = 0;
  Vec3 centroid = Vec3::Zero();
  Mat3 inertia_per_density = Mat3::Zero();
};
ShapeMassProperties ComputeShapeMassProperties(const RigidShape& shape);

}  // namespace surge

// Rigid obstacles (DESIGN §6, issue #5): shape, motion and contact law of one structure, as the
// scene builder hands it to the run. Geometry queries live in geometry.cpp (primitives, closed
// form) and mesh_distance.cpp (triangle meshes, FCL); the node contact in contact.cpp.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "core/math.h"

namespace surge {

class MeshDistanceField;  // mesh_distance.h

// Shapes are given in world coordinates at t = 0 (the obstacle's reference pose).
struct PlaneShape {  // half-space: the structure is the side opposite to `normal`
  Vec3 point = Vec3::Zero();   // a point on the plane [m]
  Vec3 normal = Vec3::UnitY(); // unit, from the structure into the material (seed App. B Fig. B.6)
};
struct BoxShape {  // axis-aligned in the reference pose; faces x-, x+, y-, y+, z-, z+
  Vec3 min = Vec3::Zero();  // [m]
  Vec3 max = Vec3::Zero();  // [m]
};
struct SphereShape {  // a disk (a cylinder along z) in 2-D; one face "surface"
  Vec3 center = Vec3::Zero();  // [m]
  Real radius = 0;             // [m]
};
struct CylinderShape {  // 3-D; faces "side", "base", "top"
  Vec3 base = Vec3::Zero();  // centre of the base disk [m]
  Vec3 top = Vec3::Zero();   // centre of the top disk [m]
  Real radius = 0;           // [m]
};
struct PolygonShape {  // simple xy polygon extruded over [z0, z1] (infinite in z in 2-D);
                       // faces "edge0".."edge<n-1>" (edge k runs from point k to k+1), "z-", "z+"
  std::vector<std::array<Real, 2>> points;  // [m]
  Real z0 = 0;  // [m] (3-D only)
  Real z1 = 0;  // [m] (3-D only)
};
struct MeshShape {  // triangle mesh (3-D), after scale / rotation / translation
  std::string file;
  std::shared_ptr<const MeshDistanceField> field;  // BVH + pseudo-normals, built by the builder
};
using ObstacleShape =
    std::variant<PlaneShape, BoxShape, SphereShape, CylinderShape, PolygonShape, MeshShape>;

enum class ObstacleMotionKind { kFixed, kPrescribed, kDynamic };

// Prescribed rigid motion: x(t) = c(t) + R(t) (x0 - c0), c(t) = c0 + v t, R(t) = exp(t [omega]x).
// Dynamic (Bullet, src/rigid): the same map with c(t), R(t) and the velocities taken from the
// body's RigidBodyState in State::rigid; c0 is the reference point.
struct ObstacleMotion {
  ObstacleMotionKind kind = ObstacleMotionKind::kFixed;
  Vec3 velocity = Vec3::Zero();          // v [m/s] (dynamic: initial)
  Vec3 angular_velocity = Vec3::Zero();  // omega [rad/s] (2-D: z component only; dynamic: initial)
  Vec3 center = Vec3::Zero();            // c0: centre of rotation (dynamic: of mass) at t = 0 [m]
  // Prescribed by a time table instead (when not empty): rows {t, dx, dy, dz}, t increasing, the
  // displacement of the centre, linearly interpolated (held constant outside the table), no
  // rotation; velocity = the slope of the current segment.
  std::vector<std::array<Real, 4>> table;
  // Dynamic only (exactly one of mass and density is > 0).
  int body = -1;          // index into State::rigid
  Real mass = 0;          // [kg]
  Real density = 0;       // [kg/m^3]: mass = density x volume of the shape (Bullet shape)
  Real restitution = 0;   // Bullet collisions with other rigid bodies and walls [-]
};

// State of a dynamic obstacle (part of State: a checkpoint holds it), for its reference point
// c0 = ObstacleMotion::center (which is also its Obstacle::reference_point).
struct RigidBodyState {
  Vec3 position = Vec3::Zero();          // where c0 is now, c(t) [m]
  Mat3 rotation = Mat3::Identity();      // R(t), relative to the reference pose at t = 0
  Vec3 velocity = Vec3::Zero();          // of that point [m/s]
  Vec3 angular_velocity = Vec3::Zero();  // world frame [rad/s]
};

// Node contact law (Bardenhagen et al. 2000, eq. (11); Anura3D manual §6.2): no penetration,
// Coulomb friction |dv_t| <= mu |dv_n|, released in tension when separable.
struct ObstacleContact {
  Real friction = 0;      // Coulomb coefficient mu [-]
  bool separable = true;  // false: sticky (bilateral in the normal direction)
  Real adhesion = 0;      // separable only: tensile strength of the contact [Pa]; a node is
                          // released once pulling it back would need more than adhesion x h^(d-1)
  // faces: interpolated (true, the default): a planar face of a box or plane constrains the
  // velocity the kernel interpolates at the face, on each node column through it, so that the
  // face's position within a cell reaches the solution (contact.cpp, docs/obstacle-faces.md);
  // nodes (false): every node on or inside the obstacle is constrained on its own.
  bool interpolated_faces = true;
  // gap_test (true, the default): the contact acts only at nodes in the stencil of a particle
  // that touches the obstacle (signed distance <= 1.5 x its half-size), so that material a cell
  // or two away is not stopped short of the surface (docs/obstacle-faces.md); false: at every
  // node with mass the contact reaches.
  bool gap_test = true;
};

struct Obstacle {
  std::string name;                  // [A-Za-z0-9_-]+, HDF5 group and CSV file name
  ObstacleShape shape;
  ObstacleMotion motion;
  ObstacleContact contact;
  Vec3 reference_point = Vec3::Zero();  // torque is taken about this point (moves with the body) [m]
  std::vector<std::string> faces;       // face names, in the order of ObstacleForce::faces
  // Bit k set: face k lies on or beyond the domain boundary (a barrier's foot on the floor) and
  // never acts, so material running up the exposed face next to it is not blocked there.
  uint64_t buried_faces = 0;
  Vec3 bounds_min = Vec3::Zero();       // world AABB at t = 0 [m] (planes: +-infinity)
  Vec3 bounds_max = Vec3::Zero();
};

// A force sensor: an axis-aligned box on the grid that sums the reactions of every structure
// (domain walls and obstacles) at the grid nodes inside it (issue #5), e.g. one strip of a wall.
struct Sensor {
  std::string name;          // [A-Za-z0-9_-]+, unique among obstacles and sensors
  Vec3 min = Vec3::Zero();   // [m] (2-D: z ignored)
  Vec3 max = Vec3::Zero();   // [m]
};

}  // namespace surge

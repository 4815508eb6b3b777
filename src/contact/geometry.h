// Where a point lies relative to an obstacle: signed distance, the outward normals of the faces
// it touches and the obstacle's velocity there (issue #5). Primitives have closed forms here
// (geometry.cpp); meshes go through MeshDistanceField (mesh_distance.cpp, FCL).
#pragma once
#include <array>
#include <vector>

#include "contact/obstacle.h"
#include "core/math.h"

namespace surge {

// Rigid pose of an obstacle at time t: a reference point x0 maps to c + R (x0 - c0).
struct ObstaclePose {
  Mat3 rotation = Mat3::Identity();      // R
  Vec3 center = Vec3::Zero();            // c(t) [m]
  Vec3 center0 = Vec3::Zero();           // c0 [m]
  Vec3 velocity = Vec3::Zero();          // dc/dt [m/s]
  Vec3 angular_velocity = Vec3::Zero();  // omega [rad/s]

  Vec3 ToReference(const Vec3& x) const { return center0 + rotation.transpose() * (x - center); }
  Vec3 ToWorld(const Vec3& x0) const { return center + rotation * (x0 - center0); }
  // Rigid-body velocity field v + omega x (x - c).
  Vec3 PointVelocity(const Vec3& x) const { return velocity + angular_velocity.cross(x - center); }
};

// Pose of an obstacle at time t (obstacle.h ObstacleMotion). A dynamic obstacle's pose is its
// entry of `rigid` (State::rigid), whatever t; without `rigid` it is the reference pose.
ObstaclePose PoseAt(const Obstacle& obstacle, Real t,
                    const std::vector<RigidBodyState>* rigid = nullptr);

// Up to three faces act at one point: edges and corners of boxes, cylinder rims, polygon
// vertices (seed spec §5.2 [REC]: constrain the span of all active normals, keep each face's
// normal for force attribution).
inline constexpr int kMaxContactFaces = 3;

struct SurfaceQuery {
  Real distance = 0;  // signed: < 0 inside the structure [m]
  int count = 0;      // active faces (filled only when distance <= tolerance)
  std::array<Vec3, kMaxContactFaces> normal{};  // outward unit normals, world frame
  std::array<int, kMaxContactFaces> face{};     // indices into Obstacle::faces
  // The face a point inside leaves through (ProjectParticlesOutOfObstacles): the nearest exposed
  // face, its signed distance (< 0 inside) and outward normal (world frame); -1 when there is
  // none. It differs from `distance` and face[0] only for boxes and cylinders with buried faces
  // (Obstacle::buried_faces): there `distance` may be a buried face's, which the grid contact
  // keeps (a slab box between two walls: every node within a cell of a wall), but a particle
  // moved by it along an exposed face's normal would stay inside.
  Real exit_distance = 0;
  Vec3 exit_normal = Vec3::Zero();
  int exit_face = -1;
};

// Signed distance of world point x to the obstacle at `pose`, and, when distance <= tolerance,
// the faces the point is on or under: every face whose own distance is within `tolerance` of the
// largest (the nearest face from inside; two or three at edges and corners). `dim` = 2 ignores
// z (extrusions along z). `band`: beyond this distance the value may be any number > band.
SurfaceQuery QueryObstacle(const Obstacle& obstacle, const ObstaclePose& pose, const Vec3& x,
                           int dim, Real tolerance, Real band);

// World bounding box of the obstacle at `pose` (+-infinity for planes).
void PosedBounds(const Obstacle& obstacle, const ObstaclePose& pose, Vec3& lo, Vec3& hi);

// Obstacle::buried_faces of a fixed shape: the planar faces whose outward normal is a coordinate
// direction and which lie on or beyond that side of the domain box [lo, hi] (within tol), e.g. a
// barrier's foot standing on the floor. Planes and meshes have none.
uint64_t BuriedFaces(const ObstacleShape& shape, int dim, const Vec3& lo, const Vec3& hi, Real tol);

// Face names of a shape (Obstacle::faces) and its bounds at t = 0; used by the scene builder.
std::vector<std::string> FaceNames(const ObstacleShape& shape, int dim);
void ReferenceBounds(const ObstacleShape& shape, int dim, Vec3& lo, Vec3& hi);

}  // namespace surge

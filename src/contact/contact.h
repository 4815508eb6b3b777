// Node contact with rigid obstacles and the reaction force on each (issue #5; seed spec §5.3;
// Bardenhagen et al. 2000, eq. (11); Anura3D manual §6.2). Runs after the grid update (domain
// walls) on v_{n+1}; the FLIP increment then carries the constraint to the particles, and the
// momentum removed at a node is the reaction impulse.
#pragma once
#include <utility>
#include <vector>

#include "contact/contact_report.h"
#include "contact/geometry.h"
#include "core/model.h"
#include "core/particles.h"
#include "core/step_context.h"
#include "grid/sparse_grid.h"

namespace surge {

// A particle the projection moved: its obstacle and face, and the force and torque (about the
// reference point) its momentum change puts on the structure.
struct ProjectedParticle {
  size_t particle = 0;
  uint32_t obstacle = 0;
  int32_t face = -1;
  Vec3 force = Vec3::Zero();   // [N]
  Vec3 torque = Vec3::Zero();  // [N m]
};

// Reused between steps (no allocation per step after warm-up).
struct ContactScratch {
  std::vector<int32_t> blocks;  // candidate blocks of one obstacle (broad phase)
  std::vector<Real> partial;    // per candidate block: sums (layout in contact.cpp)
  std::vector<uint8_t> near_block;     // per grid block: a node with mass within 2 h of an obstacle
  std::vector<std::vector<ProjectedParticle>> moved;  // per reduction chunk (projection)
  std::vector<ObstaclePose> poses;     // per obstacle at t_{n+1}
  std::vector<Vec3> lo, hi, ref;       // posed bounds and reference points
};

// For every obstacle in Model order, at its pose at t_{n+1} = ctx.time + ctx.dt (dynamic
// obstacles: their state in `rigid`, State::rigid, i.e. at t_n: explicit coupling): each grid node
// with mass on or inside it (signed distance <= 1e-9 h) gets, relative to the obstacle's
// velocity there, its approaching normal velocity removed on every active face (all of it when
// the contact is not separable) and Coulomb friction |dv_t| <= mu |dv_n| on the tangential part.
// Writes grid.velocity_new. When `report` is non-null, (*report)[o] receives obstacle o's force
// (sum of m (v_before - v_after) / dt), torque, contact area, wetted height, per-face sums.
void ApplyObstacleContact(const Model& model, const StepContext& ctx,
                          const std::vector<RigidBodyState>& rigid, SparseGrid& grid,
                          ContactScratch& scratch, std::vector<ObstacleForce>* report);

// After the position update: a particle found inside an obstacle (possible within half a cell
// of the surface, where the stencil still reaches free nodes) is put back on the surface along
// the nearest face normal and loses its approaching normal velocity relative to the obstacle.
// The momentum removed, m_p dv / dt, is added to (*report)[o].force, torque and the face's force so that the
// logged impulse stays equal to the momentum the obstacle took. Deterministic for any thread
// count. The same force is added to grid.reaction at the node nearest to the particle (for the
// force sensors). Only particles binned (grid.particle_block) in a block that ApplyObstacleContact marked
// near an obstacle, or whose +x/+y/+z neighbours it marked, are tested: a particle that ends
// inside lies within half a cell of the surface, so a node of its stencil lies within 2 h of it.
// Returns the number of particles moved.
int64_t ProjectParticlesOutOfObstacles(const Model& model, const StepContext& ctx,
                                       const std::vector<RigidBodyState>& rigid,
                                       SparseGrid& grid, Particles& particles,
                                       ContactScratch& scratch, std::vector<ObstacleForce>* report);

// Force sensors: (*out)[s] receives the sum of grid.reaction over the nodes inside sensor s
// (force on the structures there, the particle-projection share included when it has run), its
// moment about the box centre, the nodes with a non-zero reaction (contact nodes, area h^(d-1)
// each), the largest nodal force and the wetted height above the box bottom.
void SumSensors(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                ContactScratch& scratch, std::vector<ObstacleForce>& out);

// Unit vector opposite to gravity (+y when there is none): "up" for wetted heights.
Vec3 UpDirection(const Model& model);

}  // namespace surge

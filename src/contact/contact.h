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

// A node of a column through a planar face with the interpolated face constraint (contact.cpp).
struct ColumnNode {
  int32_t face = 0;   // index into the obstacle's column faces
  int32_t row = 0;    // node index along the column axis
  int64_t column = 0; // the node's indices along the other two axes, packed
  size_t node = 0;    // grid node index
  Real weight = 0;    // 1-D kernel weight of the node at the face, along the column
};

// Reused between steps (no allocation per step after warm-up).
struct ContactScratch {
  std::vector<int32_t> blocks;  // candidate blocks of one obstacle (broad phase)
  std::vector<Real> partial;    // per candidate block: sums (layout in contact.cpp)
  std::vector<uint8_t> near_block;     // per grid block: a node with mass within 2 h of an obstacle
  std::vector<std::vector<ProjectedParticle>> moved;  // per reduction chunk (projection)
  std::vector<ObstaclePose> poses;     // per obstacle at t_{n+1}
  std::vector<Vec3> lo, hi, ref;       // posed bounds and reference points
  std::vector<std::vector<ColumnNode>> column_nodes;  // per candidate block (face constraint)
  std::vector<ColumnNode> columns;     // all of them, sorted by face, column, row
  std::vector<Real> gap;               // per grid node: smallest gap of a near particle [m]
  std::vector<uint8_t> candidate;      // per grid block: met by the broad phase
};

// For every obstacle in Model order, at its pose at t_{n+1} = ctx.time + ctx.dt (dynamic
// obstacles: their state in `rigid`, State::rigid, i.e. at t_n: explicit coupling): each grid node
// with mass on or inside it (signed distance <= 1e-9 h) gets, relative to the obstacle's
// velocity there, its approaching normal velocity removed on every active face (all of it when
// the contact is not separable) and Coulomb friction |dv_t| <= mu |dv_n| on the tangential part.
// Planar faces of boxes and planes with ObstacleContact::interpolated_faces act instead on each
// node column through them: the face velocity sum_j N_j (v_j - v_o) . n that the kernel
// interpolates at the face (N_j the 1-D weights along the column) is made zero by the
// mass-weighted least change, so a face between two node planes is felt where it lies.
// Writes grid.velocity_new. When `report` is non-null, (*report)[o] receives obstacle o's force
// (sum of m (v_before - v_after) / dt), torque, contact area, wetted height, per-face sums.
// With ObstacleContact::gap_test and `particles` given, the contact is speculative: a node (a
// face column) in the stencil of particles whose domains lie a gap g >= 0 short of the surface
// (g = max(d - 1.5 r, 0), r = V0^(1/d) / 2, the smallest of them) may still approach at g / dt,
// so that the material closes the gap within the step and no further; nodes no particle within
// 2 h reaches are left free; adhesion and sticky contact act only where a particle touches
// (g = 0). Without the gap test, every node with mass is constrained at once.
void ApplyObstacleContact(const Model& model, const StepContext& ctx,
                          const std::vector<RigidBodyState>& rigid, SparseGrid& grid,
                          ContactScratch& scratch, std::vector<ObstacleForce>* report,
                          const Particles* particles = nullptr);

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

// Particle shifting by the delta-correction (Chandra, Hashimoto, Matsumi, Kamrin & Soga 2024,
// "Stabilized mixed material point method for incompressible fluid flow analysis", CMAME
// 419:116644; the form of Tesserae.jl's dam-break example, `particle_shifting`): particles that
// crowd, so that the particle volume mapped to a node exceeds the node's own volume, are moved
// down the gradient of the excess. Positions only: velocity, F, stress and history are kept.
// docs/antilocking.md, "Particle shifting".
//
//   mapped volume     V~_i = sum_p N_ip V_p,  V_p = J_p V0_p
//   node volume       V_i = h^d, less next to a closed wall (NodeVolume)
//   excess            E_i = max(0, V~_i - V_i)
//   gradient          g_p = d(sum_i E_i^2)/dx_p = 2 V_p sum_i E_i grad N_ip
//   step              x_p <- x_p - b0 g_p,  b0 = sum_i E_i^2 / sum_p |g_p|^2
//
// b0 is the step along -g that would remove sum E^2 if it were linear in x (a Newton step on
// the squared excess). Only particles of materials with `particle_shifting` move; every
// particle counts in V~_i. The excess is one-sided, so a free surface (nodes not full) pulls
// nothing. A shift that would leave the domain box is not made.
#pragma once
#include <vector>

#include "core/math.h"
#include "core/model.h"
#include "core/particles.h"
#include "core/state.h"
#include "contact/geometry.h"
#include "core/step_context.h"
#include "grid/sparse_grid.h"

namespace surge {

struct ShiftingScratch {
  std::vector<Real> excess;  // E_i per grid slot [m^d] (first V~_i)
  std::vector<Vec3> shift;   // -b0 g_p per particle [m]; zero for particles that do not move
  std::vector<Real> partial; // per-block (then per-chunk) partial sums, combined in a fixed order
  Real excess_sq = 0;        // sum_i E_i^2 of the last step [m^2d] (diagnostics, tests)
  std::vector<ObstaclePose> poses;  // per obstacle at t_n
};

bool AnyParticleShifting(const Model& model);

// Integral of the quadratic B-spline N(xi) (xi in cell units) over xi >= a: the share of a
// node's 1-D volume on the far side of a wall at distance a (cell units) from it.
Real QuadraticBsplineTail(Real a);

// Share of a node's volume on its side of a plane at signed distance a (cell units, > 0: the node
// outside) along the plane's normal: the larger of the B-spline's integral there, 1 - Tail(a),
// and the node's cell [-1/2, 1/2] there, so that a regular particle lattice maps no excess
// (NodeVolume).
Real NodeShareOutside(Real a);

// Node volume V_i [m^d] at node index `node` (node position node * dx): h^d inside; where the
// support crosses a closed wall, per axis NodeShareOutside of the wall (an open side takes the
// whole support); near an obstacle (`poses`: each obstacle's pose, Model order; empty: none), times
// NodeShareOutside of its surface at the node's signed distance (a plane through the nearest
// surface point). Pre: model.shape is the quadratic B-spline.
Real NodeVolume(const Model& model, const Vec3i& node, const std::vector<ObstaclePose>& poses = {});

// From the particles at x_n and the grid binned there (after the grid update, before G2P):
// scratch.shift of every particle.
// Obstacles count as walls (NodeVolume), at their pose at t_n (dynamic ones: `rigid`).
void ComputeParticleShift(const Model& model, const StepContext& ctx,
                          const std::vector<MaterialGroup>& groups, const Particles& particles,
                          const std::vector<RigidBodyState>& rigid, const SparseGrid& grid,
                          ShiftingScratch& scratch);

// x_{n+1} += shift for the particles whose shifted position stays inside the domain box.
void ApplyParticleShift(const Model& model, Particles& particles, const ShiftingScratch& scratch);

}  // namespace surge

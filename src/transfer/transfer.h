// The transfer stages of the explicit MPM cycle (Mast 2013, Fig. 2.1, eqs. (2.12)-(2.22)).
// Each reads what its comment says and writes only its outputs.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "contact/contact_report.h"
#include "core/model.h"
#include "core/particles.h"
#include "core/step_context.h"
#include "grid/sparse_grid.h"

namespace surge {

// Activates the blocks under every particle's stencil, numbers them, builds the neighbour and
// colour tables, bins particles by owner block (stable in particle index) and zeroes the node
// fields. Reads x. Writes grid topology, binning and node arrays.
// It also runs the gap test at the domain walls (docs/walls.md, "Stand-off"; WallTouchMarker in
// walls.h): for each active wall it marks the node columns normal to it in which a particle
// touches the wall, i.e. lies within 1.5 of its half-size r_p = V0^(1/d) / 2 of the plane (a
// particle seeded against a wall sits at r_p); the columns marked are those of the nodes its
// kernel reaches along the wall. ApplyWalls then acts only in marked columns, so a body that
// moves onto a wall is stopped when it reaches it, not when its particles reach the wall nodes'
// support (about one cell early). Writes grid.wall_touch; with Model::wall_gap_test off, clears
// the maps (every wall acts everywhere).
void RebuildGrid(const Model& model, const Particles& particles, SparseGrid& grid);

// Recomputes block_begin and sorted from grid.particle_block (stable counting sort).
void BinParticles(SparseGrid& grid);

// P2G (2.12): lumped mass, momentum (with the APIC affine term when selected), internal force
// -sum V_p sigma_p grad N_ip and particle traction forces; with body contacts
// (Model::field_count > 0) also per field, plus each field's mass gradient. Race-free and deterministic: blocks
// of one colour never share nodes; every node sum has a fixed order for any thread count.
void ParticleToGrid(const Model& model, const StepContext& ctx, const Particles& particles,
                    SparseGrid& grid);

// Per-face wall results of one grid update.
struct WallReport {
  std::array<Vec3, 6> force{};   // reaction force on each wall (on the wall, from the material) [N]
  std::array<Vec3, 6> torque{};  // moment of that force about the origin [N m]
  std::array<int64_t, 6> contact_nodes{};  // wall nodes with mass (seed BArea, eq. (7.15))
  Real max_nodal_force = 0;      // largest |nodal reaction| over all walls [N]
  Real max_elevation = 0;        // highest wall node with mass along -g (UpDirection) [m]
  Real work = 0;                 // work of all walls on the material during this step [J]
};

// Grid solve (2.13)-(2.14) and domain walls (seed Planar / Fixed nodes, spec §5.3): v_n = p/m,
// v_{n+1} = v_n + dt (f/m + g), then the wall constraints on v_{n+1}. Nodes with no mass get
// zero velocity. Reads mass, momentum, force. Writes velocity (in momentum's buffer, which it
// takes over: momentum is left empty or stale, SparseGrid::momentum), velocity_new, reaction (the
// walls' share; sensors only), report.
void UpdateGridVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid,
                        WallReport& report);

// Mirrored ghost nodes at domain walls (docs/walls.md): a node with mass beyond a wall (outside
// the domain, not on the wall plane) takes minus the normal velocity v_{n+1} of its mirror image
// across the wall plane, so that the interpolated normal velocity sum_i N_i v_i vanishes on the
// plane for every symmetric kernel (quadratic and cubic B-splines reach past the wall; linear
// does not). With Model::ghost_nodes kMirror (bilateral walls) or kFoldAll (separable slip walls
// too) the ghost's mass and unconstrained momentum are first folded into its mirror node (every
// component at a no-slip wall). On a separable wall a ghost whose mirror moves away from the
// wall keeps its own constraint. With `report`, the momentum this moves is added to the walls'
// reactions. `collect`: the call after the grid update, which lists the ghost nodes
// (grid.ghosts) and folds the ghosts' free predictions v_n + dt (f/m + g); otherwise the MUSL
// re-map, which reuses the list and folds the re-mapped velocities.
// Pre: v_{n+1} constrained by ApplyWalls at every node (UpdateGridVelocity).
void MirrorGhostNodes(const Model& model, const StepContext& ctx, SparseGrid& grid, bool collect,
                      WallReport* report);

// Local damping (Anura3D manual §6.3.1, (6.22)-(6.23); docs/antilocking.md) with the factor
// ctx.damping on the components of v_{n+1} that no wall or obstacle constrained. Reads mass,
// force, velocity (v_n); writes velocity_new. Pre: UpdateGridVelocity and the obstacle contact
// ran this step, ctx.damping > 0.
// With `balance` (the equilibrium rule, Anura3D §6.4), also the squared norms for the force ratio
// (6.29): `unbalanced` sums (m a_d)^2 = (f_d + m g_d)^2 over the components that no constraint
// changed (the free degrees of freedom; a prescribed one carries a reaction instead), `external`
// sums (m g_d)^2 over every component of every node with mass (the gravity load; tractions are
// part of f and not separated). Per-block partials in `balance->partials`, added in block order:
// the same for any thread count.
struct DampingBalance {
  std::vector<Real> partials;  // scratch, 2 per block
  Real unbalanced = 0, external = 0;  // [N^2]
};
void ApplyLocalDamping(const StepContext& ctx, SparseGrid& grid, DampingBalance* balance = nullptr);

// Contact between MPM bodies of the last step (ApplyBodyContact).
struct BodyContactReport {
  std::vector<Vec3> force;    // by velocity field: force the other bodies exert on it [N]
  int64_t contact_nodes = 0;  // nodes where two or more fields have mass
  // By Model::body_contacts: the force on the pair's normal body from the other (BodyContact::
  // name); torque about the origin; contact nodes = nodes where the correction acted on it;
  // wetted height = extent of those nodes along -g.
  std::vector<ObstacleForce> pairs;
};

// Per-body velocity fields (Model::body_contacts; body_contact.cpp has the algorithm and its
// sources): at nodes where two or more fields have mass, corrects each field's velocity against
// the common one (no interpenetration, Coulomb friction, free separation), then applies the
// walls to each field. Run after the grid update, the local damping and the obstacle contact
// (the damped common velocity is the one the fields are corrected against). Reads the field
// arrays of ParticleToGrid and the common velocity, velocity_new. Writes field_velocity,
// field_velocity_new, reaction (sensors only); adds the walls' extra reaction to walls_report.
// With `gaps` (BodyContactGaps of this step), separable pairs with gap_test are speculative
// where their particles have not met: see body_contact.cpp, step 3.
struct BodyContactGaps;
void ApplyBodyContact(const Model& model, const StepContext& ctx, SparseGrid& grid,
                      WallReport& walls_report, BodyContactReport& report,
                      const BodyContactGaps* gaps = nullptr);

// The speculative gap test between MPM bodies (BodyContact::gap_test; the obstacles' gap test,
// contact.cpp ObstacleGaps, between two bodies): at every node where two or more fields have mass
// and the two heaviest form a pair with the test, the pair's normal n (outward of its normal body
// `master`, as ApplyBodyContact takes it), and over the particles whose stencil holds the node the
// front of the master body, max (x_p - x_i).n + r_p, and of the other, min (x_p - x_i).n - r_p
// (r_p = V0^(1/d) / 2, half the particle spacing). gap = other's front - master's front when
// positive: the bodies' particles have not met along n there. Max and min are the same in any
// order: the result does not depend on the thread count. Reads the field arrays of
// ParticleToGrid and x_n.
struct BodyContactGaps {
  std::vector<int8_t> master, other;  // fields of the tested pair at each node; -1: no test
  std::vector<Vec3> normal;           // n, outward of the master body
  std::vector<Real> front_master, front_other;  // [m] along n from the node
  Real Gap(size_t i) const {
    const Real g = front_other[i] - front_master[i];
    return master[i] >= 0 && std::isfinite(g) && g > 0 ? g : 0;
  }
};
void ComputeBodyContactGaps(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                            const Particles& particles, BodyContactGaps& gaps);

// Index into Model::body_contacts of the pair of fields (f, g), [f * field_count + g], or -1.
std::vector<int> BodyContactPairTable(const Model& model);

// Receives the velocity gradients L_p (2.17) of one run of G2P (grid.runs[run]) as soon as the run
// is gathered: L[k] of particle ids[k], k < n, ids in the run's sorted order. Runs are handed over
// concurrently, each once. The step fuses the stress update into G2P this way where nothing else
// reads L (MakePipeline), so no per-particle L array is stored.
using GradientSink =
    std::function<void(size_t run, const uint32_t* ids, const Mat3* L, size_t n)>;

// G2P (2.22) with the selected transfer (FLIP increment, PIC/FLIP blend, APIC) and the position
// update x += dt sum N v_{n+1}. When velocity_gradient is non-null it also writes
// L_p = sum v_{i,n+1} (x) grad N_ip (2.17) (USL); when sink is non-null it hands L_p to it run by
// run instead. When x_new is non-null, new positions go there instead of particles.x (MUSL,
// which still needs x_n for the re-mapped gradient). With advect = false (APIC only) no position
// is written: AdvectParticles moves the particles later.
void GridToParticle(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                    Particles& particles, std::vector<Mat3>* velocity_gradient,
                    std::vector<Vec3>* x_new, const GradientSink* sink = nullptr,
                    bool advect = true);

// The deferred APIC position update x_{n+1} = x_n + dt v_p (2.16): v_p = sum N v_{i,n+1} is the
// sum G2P's own update adds, so the result is G2P's bitwise. Pre: APIC G2P with advect = false
// ran this step and nothing changed v_p since.
void AdvectParticles(const StepContext& ctx, Particles& particles);

// MUSL (Sulsky et al. 1995): re-map the updated particle momentum to the grid with the shape
// functions of x_n, recompute v_{n+1} = p/m and re-apply the walls (no reaction logged).
// Reads particles v, C, x; writes grid.momentum and grid.velocity_new.
void RemapMomentum(const Model& model, const StepContext& ctx, const Particles& particles,
                   SparseGrid& grid);

// MUSL helper: v_{n+1} = p/m from the re-mapped momentum, walls re-applied (no reaction logged).
void ApplyRemappedVelocity(const Model& model, const StepContext& ctx, SparseGrid& grid);

// L_p = sum v_{i,n+1} (x) grad N_ip from grid.velocity_new (2.17). Writes velocity_gradient.
void ComputeVelocityGradient(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                             const Particles& particles, std::vector<Mat3>& velocity_gradient);

}  // namespace surge

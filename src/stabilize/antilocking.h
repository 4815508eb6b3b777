// Volumetric anti-locking (Mast 2013 ch. 4; spec seed-algorithms.md §3): the seed's volumetric
// approach (AS1/VA) on node- or cell-based control volumes, in the seed's finite-deformation form
// (§4.4.4-4.4.5) written as an F-bar-type scaling of the increment f. docs/antilocking.md has the
// equations and measurements.
#pragma once
#include <vector>

#include "core/model.h"
#include "core/particles.h"
#include "core/state.h"
#include "core/step_context.h"
#include "grid/sparse_grid.h"

namespace surge {

// Node-sized scratch of the projection, reused every step (no allocation after warm-up).
struct AntiLockingScratch {
  std::vector<Real> weight;    // sum_p w_ip m_p over a control volume [kg]          (4.29), (4.25)
  std::vector<Real> weighted;  // sum_p w_ip m_p theta_p [kg]                        (4.29), (4.25)
  std::vector<Real> theta;     // volumetric approach: theta_p of each particle, from the scatter
  // Full-tensor approaches (AS2, AS3CV, hybrid) only; per particle, then per cell.
  std::vector<Mat3> tensor;       // the approximated field: the trial (elastic) Hencky
                                  // strain 1/2 ln b^tr (4.36)-(4.38), or tau / rho0 (step 6)
  std::vector<Mat3> inv_stretch;  // (b^tr)^(-1/2)
  std::vector<char> tensor_ok;    // b^tr positive definite (tau finite)
  std::vector<Real> theta_bar;    // hybrid: node-projected trace                    (4.34)_1
  std::vector<Real> moments;      // cell (or node) moment sums, per grid slot of the cell's lower
                                  // corner (or of the node)
  std::vector<Real> node_fit;     // node-based: the fitted components at each node   (4.31)_1
  // Strain smoothing (Anura3D §6.7) only: per node, the sum and count of the cell values around it.
  std::vector<Real> node_sum;    // (6.35)
  std::vector<Real> node_count;
};

// Replaces each anti-locked particle's velocity gradient L_p by (f-bar_p - I)/dt, where
// f_p = I + dt L_p (2.18) and f-bar_p = exp((theta-bar_p - theta_p)/dim) f_p. theta_p =
// ln(det f_p J_n) is the trace of the trial Hencky strain (4.36)-(4.38): J_n = det F_n for elastic
// solids and fluids, J^e_n = sqrt(det b^e_n) for elastoplastic models (trial elastic strain, seed
// §4.4.5). theta-bar_p is its mass-weighted L2 projection onto the control volumes and back (seed
// (4.12)-(4.13) with S = [1], M = [1 1 1 0 0 0], sums (4.24)). Node-based: theta-bar_i =
// sum N_ip m_p theta_p / sum N_ip m_p (4.29)-(4.31), theta-bar_p = sum_i N_ip theta-bar_i (4.32).
// Cell-based: theta-bar_p = sum_{p in c} m_p theta_p / sum m_p (4.25)-(4.27). The deviatoric part
// of f is untouched (P = I_dev, (4.16)). In 2-D (plane strain) only the in-plane block is
// projected: determinants of the 2x2 blocks, and the factor exp(.../2) scales that block.
// Each material group is projected over its own particles only. Reads particles (mass, volume0),
// x_n (the positions the grid transfer used), the grid topology and binning. Writes
// velocity_gradient of the anti-locked groups and scratch.
// Pre: grid built from x_n this step; velocity_gradient holds L_p (2.17) of every particle.
// Deterministic for any thread count: colour-phased block scatter as in ParticleToGrid.
void ProjectVolumetricStrain(const Model& model, const StepContext& ctx,
                             const std::vector<MaterialGroup>& groups, const Particles& particles,
                             const std::vector<Vec3>& x_n, const SparseGrid& grid,
                             AntiLockingScratch& scratch, std::vector<Mat3>& velocity_gradient);

// True when any material of the model is anti-locked (the pipeline then has the stage).
bool AnyAntiLocking(const Model& model);

// The optional stress approximation of Table 4.1 (steps 6-7) for the anti-locked groups that ask
// for it (`antilocking: {stress: true}`), with the strain's approach, control volumes and mass
// weights. Volumetric approach (AS1): the specific mean stress q_p = tr(tau_p) / (3 rho0_p) is
// projected as theta is ((4.25)_2-(4.28), (4.29)_2-(4.32)_2), and each particle's Cauchy stress
// takes the projected mean, sigma_p += (rho0_p q-bar_p / J_p - tr(sigma_p)/3) 1; the deviator is
// kept (P = I_dev). Full-tensor approaches (AS2, AS3CV, hybrid (4.35)): the specific stress
// tau_p / rho0_p is approximated component by component as the trial strain is, and replaces
// sigma_p whole (in 2-D the in-plane block; sigma_33 moves with the in-plane mean). The seed found the strain approximation alone sufficient and this step to double
// the cost (Diss. §7.5, footnote 11). Reads F, mass, volume0, x_n; writes stress of those groups
// and scratch; b^e, F and the history are not touched.
// Pre: the stress update of this step has run; grid and binning from x_n.
void ProjectStress(const Model& model, const StepContext& ctx,
                   const std::vector<MaterialGroup>& groups, Particles& particles,
                   const std::vector<Vec3>& x_n, const SparseGrid& grid,
                   AntiLockingScratch& scratch);

// True when any anti-locked material also averages its stress (the pipeline then has the stage).
bool AnyStressAveraging(const Model& model);

}  // namespace surge

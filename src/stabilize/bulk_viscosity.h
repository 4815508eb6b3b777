// Artificial bulk viscosity for shocks (von Neumann & Richtmyer 1950, J. Appl. Phys. 21:232-237;
// Wilkins 1980, J. Comput. Phys. 36:281-303; the LS-DYNA Theory Manual, "Bulk viscosity", with
// its defaults): a pressure q added to the stress of the internal force, never to the material
// state. docs/antilocking.md "Artificial bulk viscosity" has the equations and measurements.
//
// Per particle of a material with Model::bulk_viscosity enabled, from the step's rate of
// deformation tr d_p = tr L_p (after anti-locking, when on):
//   q_p = rho_p l (c0 l (tr d_p)^2 - c1 c tr d_p)  if tr d_p < 0 (compression), else 0,
// l = dx (the cell size stands in for the element length), rho_p = m_p / (V0_p det F_p), c the
// material's elastic (P-)wave speed (WaveSpeed), c0 = quadratic, c1 = linear.
// The stress the next step's ParticleToGrid reads is sigma_p - q_p 1; the material's own sigma_p
// is put back right after (bitwise), so models, outputs and energies never see q.
#pragma once
#include <cstdint>
#include <vector>

#include "core/model.h"
#include "core/particles.h"
#include "core/state.h"
#include "core/step_context.h"

namespace surge {

struct BulkViscosityScratch {
  std::vector<Real> q;        // q_p of the last step [Pa], index as the particles then
  std::vector<int64_t> id;    // Particles::id of each q entry (the particles may be reordered or
                              // removed before the next step uses q)
  std::vector<Real> by_id;    // scratch of the re-alignment, indexed by id [Pa]
  std::vector<SymMat3> saved;  // the material stress during ParticleToGrid [Pa]
  // Time-step bound of the viscous materials from the last step (LS-DYNA Theory Manual, time
  // step with bulk viscosity): dt <= l / (Q + sqrt(Q^2 + c^2) + |v|), Q = c1 c + c0 l |tr d|
  // (tr d < 0; Q = c1 c otherwise), before the Courant number. Infinity before the first step.
  Real dt_bound = 1e300;
};

// True when any material of the model has a bulk viscosity (the pipeline then has its stages).
bool AnyBulkViscosity(const Model& model);

// After UpdateStress: q_p and the time-step bound of every particle of a viscous material from
// velocity_gradient (L_p of this step), F, mass, volume0 and v; q_p = 0 for other particles.
void ComputeBulkViscosity(const Model& model, const StepContext& ctx,
                          const std::vector<MaterialGroup>& groups, const Particles& particles,
                          const std::vector<Mat3>& velocity_gradient, BulkViscosityScratch& scratch);

// Before ParticleToGrid: re-aligns q with the particles (by id, after reordering or removals),
// saves each particle's stress and subtracts q_p from its diagonal (sigma - q 1).
void ApplyBulkViscosity(Particles& particles, BulkViscosityScratch& scratch);

// After ParticleToGrid: the saved material stress back (bitwise).
void RestoreStress(Particles& particles, BulkViscosityScratch& scratch);

}  // namespace surge

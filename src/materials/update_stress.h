// Kinematics and stress update per material group (Mast 2013 eqs. (2.17)-(2.20)): one
// std::visit per group, then a monomorphic parallel loop (no per-particle virtual call).
#pragma once
#include <vector>

#include "core/end_checks.h"
#include "core/model.h"
#include "core/state.h"
#include "core/step_context.h"

namespace surge {

// F_{n+1} = (I + dt L) F_n (2.18), then the group's constitutive update. Reads L, F, stress and
// what the group's model keeps (linear_elastic: strain; plastic models: elastic_b, history; yield-
// stress fluids: history), writes F, stress and that state. With `stress_power` non-null it is
// set to P_n + P_{n+1}, P = sum_p J_p V0_p sigma_p : sym(L_p) [W] before and after the update
// (the energy record's internal work, docs/stability.md), summed in fixed chunks. With `checks`,
// each particle goes through a copy of them right after its update, and `clean` is set to whether
// every particle passed (core/end_checks.h).
void UpdateStress(const Model& model, const StepContext& ctx,
                  const std::vector<Mat3>& velocity_gradient,
                  const std::vector<MaterialGroup>& groups, Particles& particles,
                  Real* stress_power = nullptr, const EndChecks* checks = nullptr,
                  bool* clean = nullptr);

// The same update for the particles ids[0..n) with gradients velocity_gradient[0..n) (one run of
// G2P: the step fuses the stress update into G2P where nothing else reads L, docs/architecture.md).
// Particles may belong to different materials. With `energy` returns their P_n + P_{n+1} [W],
// summed in k order; else 0. With `checks`, each particle goes through checks->Test right after
// its update (core/end_checks.h).
Real UpdateStressOfRun(const Model& model, const StepContext& ctx, const uint32_t* ids,
                       const Mat3* velocity_gradient, size_t n, Particles& particles, bool energy,
                       EndChecks* checks = nullptr);

// Material history consistent with a prescribed initial Cauchy stress at F = I (a geostatic
// start): b^e from the elastic compliance for J2, identity otherwise; history slots zero.
void InitialHistory(const Material& material, const Mat3& stress, SymMat3& elastic_b,
                    History& history);

// The optional particle arrays a run with these materials needs (Particles::layout): C for APIC
// transfers, strain for linear_elastic, b^e for the elastoplastic models, history for those and
// the yield-stress fluids, ext_force when a body has tractions.
ParticleLayout ParticleLayoutFor(const Model& model, bool tractions);

// History slots a model reads and writes (Particles::history); 0 for models without history.
int HistorySlotsOf(const MaterialParams& params);

// Stored elastic energy sum psi V0 [J] (per metre of thickness in 2-D), summed in fixed chunks.
Real StrainEnergy(const Model& model, const std::vector<MaterialGroup>& groups,
                  const Particles& particles);

// Energy density of one particle [J/m^3 of reference volume].
Real StrainEnergyDensity(const Material& material, const Mat3& F, const Mat3& stress,
                         const Mat3& strain);

}  // namespace surge

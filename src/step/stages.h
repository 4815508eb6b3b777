// Stage adapters with the uniform StageFn signature; each calls one module function.
#pragma once
#include "step/step.h"

namespace surge {

// Particles are permuted into block order every this many steps (spike note: 10 is best on
// 2 threads).
inline constexpr int64_t kReorderInterval = 10;

void RebuildGridStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void ReorderParticlesStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void ParticleToGridStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void GridUpdateStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Mirrored ghost nodes at the domain walls (MirrorGhostNodes), after the obstacle contact.
void WallGhostStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Node contact with the rigid obstacles on v_{n+1} (src/contact), reactions into the report.
void ObstacleContactStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void BodyContactStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Local damping of the free components of v_{n+1} while ctx.damping > 0 (src/transfer).
void LocalDampingStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Dynamic obstacles: the step's MPM reaction (force on the structure, torque about the centre of
// mass) plus the ramped weight act on each Bullet body for dt, then State::rigid takes the new
// poses and velocities (src/rigid; DESIGN §4 step 6).
void RigidBodiesStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Force sensors: node reactions summed over each sensor box (src/contact).
void SensorsStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Particles that ended inside an obstacle go back to its surface (src/contact).
void ObstacleProjectionStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void GridToParticleUslStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// USL where nothing reads L_p but the stress update (no anti-locking, no bulk viscosity): G2P hands
// each run's L_p to UpdateStressOfRun as soon as the run is gathered, instead of storing L_p for
// UpdateStressStage (no L array: 72 bytes per particle less; docs/benchmarks.md). Same results
// bitwise; its clock (grid_to_particle) includes the stress update.
void GridToParticleStressStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// The same, and the run's particles then pass through the domain-exit test and the fast test of
// the health check while they are in cache: where nothing after G2P moves a particle or changes its
// v, F or stress before DomainExitStage (no particle shifting, no deferred advection, no stress
// averaging; an obstacle's projection tests again the particles it moves), a step whose particles
// all pass skips both stages' passes over the particles (docs/benchmarks.md).
void GridToParticleStressCheckStage(const Model&, const StepContext&, State&, Workspace&,
                                    StepReport&);
void GridToParticleMuslStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void RemapMomentumStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void VelocityGradientStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// USL with anti-locking and FLIP or PIC-FLIP (APIC defers instead, below): G2P writes L_p and
// x_{n+1} to scratch, then commits x_{n+1} by a swap, so that (as after MUSL's VelocityGradient)
// Workspace::x_new holds x_n for AntiLocking.
void GridToParticleUslKeepStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// USL with anti-locking and APIC (DeferredAdvection): G2P writes v_p, C_p and L_p and leaves the
// particles at x_n; AdvectStage moves them to x_{n+1} = x_n + dt v_p after the stress stages.
void GridToParticleUslDeferStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void AdvectStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// Volumetric anti-locking of L_p (src/stabilize) with the shape functions at x_n (the particles'
// positions with deferred advection, else Workspace::x_new).
void AntiLockingStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void StressAveragingStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void UpdateStressStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
// With deferred advection and nothing between the stress update and AdvectStage (no stress
// averaging) nor after it that moves every particle (no particle shifting): UpdateStressStage,
// then each particle is advected and passes the end checks right after its update, in place of
// AdvectStage and, when all pass, of DomainExitStage's and CheckStateStage's passes. Bitwise the
// same state; the advection's time is in the update_stress clock.
void UpdateStressAdvectCheckStage(const Model&, const StepContext&, State&, Workspace&,
                                  StepReport&);
// Artificial bulk viscosity (src/stabilize/bulk_viscosity.h): q_p from this step's L_p (after
// UpdateStress), sigma - q 1 for ParticleToGrid (before it) and the material stress back (after).
void BulkViscosityRateStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void BulkViscosityApplyStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void BulkViscosityRestoreStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void ParticleShiftComputeStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void ParticleShiftApplyStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void DomainExitStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void CheckStateStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);
void EnergyStage(const Model&, const StepContext&, State&, Workspace&, StepReport&);

// What the force log records (DESIGN §7): "domain" (the walled faces) when a wall is not open,
// then every obstacle with its faces, then every force sensor (no faces).
std::vector<ForceChannel> ForceChannels(const Model& model);
// The step's reactions in ForceChannels order.
void CollectForces(const Model& model, const StepReport& step, ContactReport& out);

// End-of-step energies of a state (also used by tests and the run summary).
EnergyRecord ComputeEnergy(const Model& model, const State& state);

}  // namespace surge

// The explicit MPM step (Mast 2013, Fig. 2.1): a pipeline of named, timed stages assembled once
// from the Model (DESIGN §4). Read step.cpp first: it is the whole cycle.
#pragma once
#include <array>
#include <vector>

#include "contact/contact_report.h"
#include "core/model.h"
#include "core/stage.h"
#include "core/state.h"
#include "core/step_context.h"
#include "core/step_report.h"
#include "step/workspace.h"

namespace surge {

struct StepReport {
  StageSeconds stage_seconds{};  // cumulative wall time per stage [s]
  EnergyRecord energy;           // end-of-step energies (when the energy stage is in the pipeline)
  Health health;                 // first problem found by CheckState / DomainExit / time step
  WallReport walls;              // wall reactions of the last step
  std::vector<ObstacleForce> obstacles;  // obstacle reactions of the last step (Model order)
  std::vector<ObstacleForce> sensors;    // force-sensor sums of the last step (Model order)
  BodyContactReport body_contact;        // MPM-MPM contact of the last step (body contacts only)
  int64_t removed_last_step = 0; // particles removed through open sides in the last step
  // Local damping's equilibrium rule (LocalDamping::Equilibrium), while it watches: the force
  // ratio (6.29) and energy ratio (6.30) of the last step, and whether they released the damping.
  Real force_ratio = 0, energy_ratio = 0;
  bool damping_released = false;
};

using StageFn = void (*)(const Model&, const StepContext&, State&, Workspace&, StepReport&);

struct PipelineStage {
  Stage stage;
  StageFn run;
};

using Pipeline = std::vector<PipelineStage>;

// The stages this model needs, in cycle order; unneeded stages are not in the list.
Pipeline MakePipeline(const Model& model);

// The per-particle scratch arrays MakePipeline's stages fill for this model (the memory
// estimate's share of Workspace and AntiLockingScratch).
StepScratch StepScratchFor(const Model& model);

// Whether G2P leaves the particles at x_n and AdvectStage moves them after the stress stages:
// APIC where a stage after G2P still needs x_n (MUSL's re-map and velocity gradient, the
// anti-locking's shape functions). APIC's particle velocity is the grid's, v_p = sum N v_{i,n+1}
// (Jiang et al. 2015, eq. (8)), so x_n + dt v_p is G2P's own x_{n+1} (2.16), bitwise, and no
// x_{n+1} array (24 bytes per particle) is needed. FLIP's v_p is not the grid's: it keeps one.
bool DeferredAdvection(const Model& model);

// Time step for the next step: CFL rule dt = C dx / max_p (c_p + |v_p|) (spec §1.7) and the
// viscous limit (ViscousTimeStep), bounded by max_dt, the fixed override and the remaining time
// to Model::time.end. Within 10 CFL steps of the end the rest is split into equal steps (no
// sliver last step, whose wall and obstacle reactions m v_n / dt would be far too large).
Real NextTimeStep(const Model& model, const State& state);

// Viscous (diffusion) limit of the explicit step over the materials that have particles:
// dt_v = C rho0 dx^2 / (2 dim eta_L), C = time.cfl, eta_L the longitudinal viscosity: 2 mu for
// newtonian_fluid (sigma = 2 mu d), 4/3 mu_max for bingham_fluid and frictional_fluid
// (sigma = 2 mu_eff dev d, mu_eff <= mu_max). Infinity when no material is viscous. Source: the
// FTCS stability bound nu dt / dx^2 <= 1 / (2 dim) of explicit diffusion (von Neumann; Press et
// al., Numerical Recipes 3rd ed. §20.2), the form Morris, Fox & Zhu (1997, J. Comput. Phys.
// 136:214-226) use for SPH (dt <= 0.125 h^2 / nu). docs/scene-reference.md, `time`.
Real ViscousTimeStep(const Model& model, const State& state);

// Advances the state by one step. After it, report.health says whether the state is usable.
void Step(const Model& model, const Pipeline& pipeline, State& state, Workspace& work,
          StepReport& report);

}  // namespace surge

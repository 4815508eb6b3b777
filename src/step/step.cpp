// THE pipeline. Stage order follows the seed cycle (Mast 2013, Fig. 2.1, eqs. (2.12)-(2.22));
// docs/architecture.md has a paragraph per stage.
//
//   USL : RebuildGrid -> ReorderParticles -> ParticleToGrid -> GridUpdate -> GridToParticle (+ L_p) -> UpdateStress
//   MUSL: RebuildGrid -> ReorderParticles -> ParticleToGrid -> GridUpdate -> GridToParticle -> RemapMomentum
//         -> VelocityGradient -> UpdateStress
//   then: [AntiLocking] -> UpdateStress -> [StressAveraging] -> [Advect] -> [ParticleShifting]
//         -> [ObstacleProjection] -> [RigidBodies] -> [Sensors] -> [BulkViscosity]
//         -> DomainExit -> CheckState -> Energy
//   AntiLocking (Mast 2013 Table 4.1) runs just before UpdateStress when a material asks for it.
//   With APIC where x_n is still needed after G2P (MUSL, anti-locking), G2P leaves the particles
//   at x_n and Advect moves them after the stress stages (DeferredAdvection).
//   BulkViscosity (when a material has one): q_p after UpdateStress, sigma - q 1 around P2G.
//   LocalDamping (scene key damping) after the grid update and the obstacles, on the free
//   components of v_{n+1} (Anura3D manual §6.3).
//   With obstacles: ObstacleContact after GridUpdate (node contact, reactions) and
//   ObstacleProjection after the positions are committed (particles back onto the surface).
//   With body contacts: BodyContact after the grid update and obstacles (per-body velocity
//   fields), and G2P reads each particle's own field.
#include "step/step.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

#include "core/parallel.h"
#include "materials/update_stress.h"
#include "stabilize/bulk_viscosity.h"
#include "step/stages.h"

namespace surge {

bool DeferredAdvection(const Model& model) {
  return model.transfer == TransferScheme::kApic &&
         (model.scheme != UpdateScheme::kUsl || AnyAntiLocking(model));
}

StepScratch StepScratchFor(const Model& model) {
  StepScratch s{};
  const bool antilocking = AnyAntiLocking(model);
  const bool usl = model.scheme == UpdateScheme::kUsl;
  // USL with nothing between G2P and the stress update that reads L_p: the update runs inside
  // G2P, run by run, and L_p is never stored (GridToParticleStressStage).
  s.velocity_gradient = !(usl && !antilocking && !AnyBulkViscosity(model));
  // MUSL's x_{n+1}; USL keeps x_n for the anti-locking's grid; neither with APIC (deferred).
  s.x_n = (!usl || antilocking) && !DeferredAdvection(model);
  s.theta = s.tensor = s.inv_stretch = s.theta_bar = false;
  s.shift = AnyParticleShifting(model);
  s.node_reaction = !model.sensors.empty();  // RebuildGrid: SparseGrid::keep_reaction
  s.node_momentum = !usl;                    // RemapMomentum's p_i beside v_{i,n}
  for (const AntiLocking& a : model.antilocking) {
    if (a.method == AntiLockingMethod::kNone) continue;
    const bool full = a.method == AntiLockingMethod::kHybrid ||
                      (a.method != AntiLockingMethod::kSmoothing &&
                       a.approach != AntiLockingApproach::kVolumetric);
    s.theta |= !full;  // ProjectVolumetricStrain, SmoothVolumetricStrain
    s.tensor |= full;  // ProjectFullTensor(Stress)
    s.inv_stretch |= full;
    s.theta_bar |= a.method == AntiLockingMethod::kHybrid;
  }
  return s;
}

Pipeline MakePipeline(const Model& model) {
  Pipeline p;
  p.push_back({Stage::kRebuildGrid, RebuildGridStage});
  p.push_back({Stage::kReorderParticles, ReorderParticlesStage});
  const bool bulk_viscosity = AnyBulkViscosity(model);
  if (bulk_viscosity) p.push_back({Stage::kBulkViscosity, BulkViscosityApplyStage});  // sigma - q 1
  p.push_back({Stage::kParticleToGrid, ParticleToGridStage});                  // (2.12)
  if (bulk_viscosity) p.push_back({Stage::kBulkViscosity, BulkViscosityRestoreStage});
  p.push_back({Stage::kGridUpdate, GridUpdateStage});                          // (2.13)-(2.14)
  const bool obstacles = !model.obstacles.empty();
  if (obstacles) p.push_back({Stage::kObstacleContact, ObstacleContactStage});  // spec §5.3
  const bool walls = std::any_of(model.walls.begin(), model.walls.begin() + 2 * model.dim,
                                 [](const Wall& w) { return w.kind != WallKind::kOpen; });
  if (model.ghost_nodes != GhostNodes::kConstrain && walls)  // docs/walls.md; timed with the grid update
    p.push_back({Stage::kGridUpdate, WallGhostStage});
  // Local damping acts on the common field, after its constraints; with body contacts the
  // per-body fields then take its velocity change as they take the walls' (body_contact.cpp).
  if (model.damping.alpha > 0) p.push_back({Stage::kLocalDamping, LocalDampingStage});  // A3D (6.23)
  if (model.field_count > 0) p.push_back({Stage::kBodyContact, BodyContactStage});  // Anura3D §6.2
  const bool antilocking = AnyAntiLocking(model);
  // USL with nothing between G2P and the stress update that reads L_p or the stress: the update
  // runs inside G2P, run by run (the stages skipped in between, obstacle projection, rigid bodies
  // and sensors, read neither F, the stress nor L_p).
  const bool fused = !StepScratchFor(model).velocity_gradient;
  // The delta-correction's shift from x_n and the grid binned there; made after G2P.
  const bool shifting = AnyParticleShifting(model);
  if (shifting) p.push_back({Stage::kParticleShifting, ParticleShiftComputeStage});
  const bool defer = DeferredAdvection(model);
  // The stages between G2P and the domain exit that could move a particle or change v, F or the
  // stress: with none, G2P also runs the domain-exit and health tests (stages.h). The obstacle
  // projection tests again the particles it moves.
  const bool end_checks = !shifting && !defer && !AnyStressAveraging(model);
  if (fused) {
    p.push_back({Stage::kGridToParticle, end_checks ? GridToParticleStressCheckStage
                                                    : GridToParticleStressStage});  // (2.17)-(2.22)
  } else if (model.scheme == UpdateScheme::kUsl) {
    p.push_back({Stage::kGridToParticle,                                       // (2.17), (2.22)
                 !antilocking ? GridToParticleUslStage
                 : defer      ? GridToParticleUslDeferStage
                              : GridToParticleUslKeepStage});
  } else {
    p.push_back({Stage::kGridToParticle, GridToParticleMuslStage});            // (2.22)
    p.push_back({Stage::kRemapMomentum, RemapMomentumStage});                  // Sulsky 1995
    p.push_back({Stage::kVelocityGradient, VelocityGradientStage});            // (2.17)
  }
  // The stress stages right after G2P: the stages that follow them (shift, obstacle projection,
  // rigid bodies, sensors) read neither L_p, F nor the stress, and the stress stages read neither
  // the positions they move nor the grid reactions; with deferred advection the anti-locking's
  // shape functions still see x_n.
  if (antilocking) p.push_back({Stage::kAntiLocking, AntiLockingStage});       // (4.25)-(4.32)
  // Deferred advection right after the stress update, nothing moving every particle after it:
  // the update advects and checks each particle (stages.h).
  const bool advect_checks = !fused && defer && !shifting && !AnyStressAveraging(model);
  if (!fused)
    p.push_back({Stage::kUpdateStress, advect_checks ? UpdateStressAdvectCheckStage    // (2.16),
                                                     : UpdateStressStage});            // (2.18)-(2.20)
  if (AnyStressAveraging(model))  // Table 4.1 steps 6-7, timed with the strain projection
    p.push_back({Stage::kAntiLocking, StressAveragingStage});
  if (defer && !advect_checks) p.push_back({Stage::kGridToParticle, AdvectStage});  // (2.16)
  if (shifting) p.push_back({Stage::kParticleShifting, ParticleShiftApplyStage});  // x_{n+1}
  if (obstacles) p.push_back({Stage::kObstacleProjection, ObstacleProjectionStage});
  const bool dynamic = std::any_of(model.obstacles.begin(), model.obstacles.end(), [](const Obstacle& o) {
    return o.motion.kind == ObstacleMotionKind::kDynamic;
  });
  if (dynamic) p.push_back({Stage::kRigidBodies, RigidBodiesStage});             // Bullet
  if (!model.sensors.empty()) p.push_back({Stage::kSensors, SensorsStage});  // all reactions in
  // After the obstacle projection: its time-step bound reads the particle speeds.
  if (bulk_viscosity) p.push_back({Stage::kBulkViscosity, BulkViscosityRateStage});  // q_p
  p.push_back({Stage::kDomainExit, DomainExitStage});
  p.push_back({Stage::kCheckState, CheckStateStage});
  if (model.output.energy) p.push_back({Stage::kEnergy, EnergyStage});
  return p;
}

void Step(const Model& model, const Pipeline& pipeline, State& state, Workspace& work,
          StepReport& report) {
  StepContext ctx;
  ctx.time = state.time;
  ctx.dt = NextTimeStep(model, state);
  if (model.time.fixed_dt <= 0 && !model.bulk_viscosity.empty() && AnyBulkViscosity(model)) {
    // Bulk viscosity stiffens the compression: the LS-DYNA bound l / (Q + sqrt(Q^2 + c^2) + |v|)
    // from the last step (bulk_viscosity.h), times the Courant number.
    ctx.dt = std::min(ctx.dt, model.time.cfl * work.bulk_viscosity.dt_bound);
  }
  ctx.dx = model.dx;
  ctx.inv_dx = 1.0 / model.dx;
  ctx.ramp = RampFactor(model, state.time);
  ctx.mass_scale = model.mass_scaling.At(state.time);  // Anura3D §6.5: beta, 1 after until
  // With mass scaling the grid's inertia is beta m_i (ParticleToGridStage) while the weight stays
  // m_i g: as an acceleration on the scaled inertia, gravity is g / beta.
  ctx.gravity = ctx.ramp * model.gravity / ctx.mass_scale;
  // Anura3D §6.3: alpha, 0 after damping.until or once the equilibrium rule released it (§6.4).
  ctx.damping = state.damping_released ? 0 : model.damping.At(state.time);
  report.damping_released = false;
  if (!(ctx.dt >= model.time.min_dt) || !std::isfinite(ctx.dt)) {
    report.health = Health{HealthStatus::kTimeStepTooSmall, -1,
                           "time step " + std::to_string(ctx.dt) + " s is below time.min_dt = " +
                               std::to_string(model.time.min_dt) +
                               " s. Likely cause: a particle speed |v| far above the wave speed "
                               "(a blow-up in progress), or a viscous or bulk-viscosity bound",
                           "time_step", "dt"};
    return;
  }

  StageClock clock(report.stage_seconds);
  for (const PipelineStage& stage : pipeline) {
    stage.run(model, ctx, state, work, report);
    clock.Lap(stage.stage);
  }
  state.time += ctx.dt;
  state.dt = ctx.dt;
  ++state.step;
  report.energy.time = state.time;
  report.energy.step = state.step;
  report.energy.dt = ctx.dt;
}

Real NextTimeStep(const Model& model, const State& state) {
  const Real remaining = model.time.end - state.time;
  Real dt = model.time.fixed_dt;
  if (dt <= 0) {
    const Particles& P = state.particles;
    Real max_speed = 0;
    // Mass scaling (Anura3D (6.31)): the wave speed in the scaled density beta rho is c/sqrt(beta).
    const Real beta = model.mass_scaling.At(state.time);
    for (const MaterialGroup& g : state.groups) {
      const Real c = WaveSpeed(model.materials[g.material]) / std::sqrt(beta);
      std::array<Real, kReductionChunks> partial{};
      ParallelChunks(g.end - g.begin, [&](size_t chunk, size_t b, size_t e) {
        Real vmax = 0;
        for (size_t p = g.begin + b; p < g.begin + e; ++p) vmax = std::max(vmax, P.v[p].squaredNorm());
        partial[chunk] = vmax;
      });
      const Real vmax = std::sqrt(*std::max_element(partial.begin(), partial.end()));
      if (g.end > g.begin) max_speed = std::max(max_speed, c + vmax);
    }
    dt = max_speed > 0 ? model.time.cfl * model.dx / max_speed : model.time.max_dt;  // spec §1.7
    // The viscous bound is proportional to the density: beta times larger while scaled.
    dt = std::min({dt, beta * ViscousTimeStep(model, state), model.time.max_dt});
    // Land exactly on the end time without a sliver step: once at most kLandingSteps CFL steps
    // remain, the rest is split into equal steps, each at least (n - 1)/n of the CFL step. A
    // sliver last step turns the momentum a wall or obstacle removes at a node, m v_n, into a
    // force m v_n / dt many times too large: the dam break's barrier force read +50 % on a last
    // step 1/48 of the others, and `surge forces` took it as the peak (docs/forces.md).
    constexpr Real kLandingSteps = 10;
    if (remaining > 0 && dt > 0) {
      const Real n = std::ceil(remaining / dt);
      if (n <= kLandingSteps) dt = remaining / n;
    }
  }
  // Land exactly on the end time (a fixed_dt is kept until the last step, which is cut short).
  if (remaining > 0 && dt > remaining) dt = remaining;
  return dt;
}

Real ViscousTimeStep(const Model& model, const State& state) {
  Real dt = std::numeric_limits<Real>::infinity();
  for (const MaterialGroup& g : state.groups) {
    if (g.end == g.begin) continue;
    const Material& m = model.materials[g.material];
    const Real eta = std::visit(  // longitudinal viscosity eta_L [Pa s]
        [](const auto& p) -> Real {
          using P = std::decay_t<decltype(p)>;
          if constexpr (std::is_same_v<P, NewtonianFluidParams>) {
            return 2 * p.viscosity;  // sigma = 2 mu d (6.2): eta_L = 2 mu
          } else if constexpr (kIsFluid<P>) {
            return 4.0 / 3.0 * p.max_viscosity;  // sigma = 2 mu_eff dev d: eta_L = 4/3 mu_max
          } else {
            return 0;
          }
        },
        m.params);
    // FTCS diffusion bound (eta_L / rho0) dt / dx^2 <= 1 / (2 dim), scaled by C.
    if (eta > 0) {
      dt = std::min(dt, model.time.cfl * m.density * model.dx * model.dx / (2 * model.dim * eta));
    }
  }
  return dt;
}

}  // namespace surge

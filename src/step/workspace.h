// Workspace: grid and per-particle scratch, rebuilt every step and never saved (STYLE H.4), except
// what a step hands to the next (bulk viscosity q_p), which checkpoints carry (io/checkpoint.h).
#pragma once
#include <memory>
#include <vector>

#include "contact/contact.h"
#include "grid/sparse_grid.h"
#include "rigid/rigid_world.h"
#include "stabilize/antilocking.h"
#include "stabilize/bulk_viscosity.h"
#include "stabilize/particle_shifting.h"
#include "transfer/transfer.h"

namespace surge {

struct Workspace {
  SparseGrid grid;
  std::vector<Mat3> velocity_gradient;  // L_p [1/s]        written by GridToParticle / VelocityGradient
  std::vector<Vec3> x_new;              // x_{n+1} [m] (MUSL) written by GridToParticle
  std::vector<Real> run_power;          // stress power per G2P run [W] (GridToParticleStressStage)
  // Per G2P run: every particle inside the domain box and past the health check's fast test
  // (GridToParticleStressCheckStage); all of them: DomainExit and CheckState skip their passes.
  std::vector<uint8_t> run_clean;
  bool end_checks_passed = false;
  std::vector<uint8_t> exit_flag;       // scratch of DomainExit and ReorderParticles
  std::vector<uint32_t> reorder;        // scratch of ReorderParticles
  AntiLockingScratch antilocking;       // node sums of AntiLocking
  ShiftingScratch shifting;             // particle shifting's node excess and particle shifts
  BulkViscosityScratch bulk_viscosity;  // q_p between steps: its q, id and dt_bound are saved
                                        // in checkpoints (io/checkpoint.h)
  ContactScratch contact;               // broad phase and partial sums of the obstacle contact
  DampingBalance damping;               // force-ratio sums of local damping's equilibrium rule
  BodyContactGaps body_gaps;            // gap test between MPM bodies (body contacts only)
  // Energy guard of EnergyStage (docs/stability.md): set on its first step of a run or restart.
  struct EnergyGuard {
    bool set = false;
    bool active = false;   // false where external work can add energy (see EnergyStage)
    Real reference = 0;    // mechanical energy above the domain floor at the first step [J]
    Real floor = 0;        // potential per kg at the domain's lowest corner [J/kg]
    Real floor_energy = 0; // floor x the particle mass now [J]
  } energy_guard;
  // Bullet world of the dynamic obstacles (built from Model + State on first use; the rigid
  // state of record is State::rigid), each dynamic body's handle and its Bullet frame at t = 0.
  std::unique_ptr<RigidWorld> rigid_world;
  std::vector<int> rigid_handle;     // by ObstacleMotion::body
  std::vector<Mat3> rigid_frame0;    // R_bullet(0) by ObstacleMotion::body
  std::vector<Vec3> rigid_offset;    // reference point in Bullet's body frame, by body
  std::vector<Real> rigid_mass;      // [kg], by body
  // Restart only (io/checkpoint.h): Bullet's own state of each dynamic body as the checkpoint
  // saved it, by body; used once, when the Bullet world is built, instead of re-deriving it from
  // State::rigid (which would round the centre of mass differently in the last bit).
  std::vector<RigidWorld::BodyState> rigid_restart;
  // Bullet's contact manifolds at the checkpoint (RigidWorld::ContactCache), restored right
  // after rigid_restart; empty when not restarting.
  std::vector<uint8_t> rigid_restart_contacts;
};

}  // namespace surge

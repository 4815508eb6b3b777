// Pipeline stages: names used in logs, HDF5 attributes and benchmark CSVs (STYLE H.3).
#pragma once
#include <array>
#include <chrono>

namespace surge {

enum class Stage : int {
  kRebuildGrid = 0,
  kReorderParticles,  // every kReorderInterval steps
  kParticleToGrid,
  kGridUpdate,
  kObstacleContact,    // only with obstacles (src/contact)
  kBodyContact,        // only with body contacts: per-body velocity fields (src/transfer)
  kLocalDamping,       // only with the scene key damping (src/transfer/grid_update.cpp)
  kGridToParticle,
  kRemapMomentum,      // MUSL only
  kVelocityGradient,   // MUSL only
  kObstacleProjection, // only with obstacles: particles inside an obstacle back to its surface
  kRigidBodies,        // only with dynamic obstacles: MPM reactions -> Bullet step (src/rigid)
  kSensors,            // only with force sensors (src/contact)
  kAntiLocking,        // only when a material is anti-locked (src/stabilize)
  kUpdateStress,
  kBulkViscosity,      // only when a material has a bulk viscosity (src/stabilize): q around P2G
  kParticleShifting,   // only when a material shifts its particles (src/stabilize)
  kDomainExit,
  kCheckState,
  kEnergy,
  kCount
};
inline constexpr int kStageCount = static_cast<int>(Stage::kCount);

const char* StageName(Stage s);

using StageSeconds = std::array<double, kStageCount>;

// Accumulates wall time per stage: Lap(s) charges the time since the last lap to stage s.
class StageClock {
 public:
  explicit StageClock(StageSeconds& sink) : sink_(sink), last_(Clock::now()) {}
  void Lap(Stage s) {
    const auto now = Clock::now();
    sink_[static_cast<int>(s)] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  using Clock = std::chrono::steady_clock;
  StageSeconds& sink_;
  Clock::time_point last_;
};

}  // namespace surge

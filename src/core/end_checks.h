// The per-particle tests of the step's last stages (DomainExitStage, CheckStateStage), shared
// with the stress updates that run them on each particle right after its update
// (GridToParticleStressCheckStage, UpdateStressAdvectCheckStage) so that those stages can skip
// their passes. ObstacleProjectionStage tests again the particles it moves.
#pragma once
#include <cmath>

#include "core/model.h"
#include "core/particles.h"

namespace surge {

// The domain box that DomainExitStage holds the particles to, and which of its sides are open.
struct DomainBox {
  int dim = 3;
  Real lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  bool open_lo[3] = {false, false, false}, open_hi[3] = {false, false, false};

  static DomainBox Of(const Model& m) {
    DomainBox b;
    b.dim = m.dim;
    for (int d = 0; d < m.dim; ++d) {
      b.lo[d] = m.domain_min[d], b.hi[d] = m.domain_max[d];
      b.open_lo[d] = m.walls[2 * d].kind == WallKind::kOpen;
      b.open_hi[d] = m.walls[2 * d + 1].kind == WallKind::kOpen;
    }
    return b;
  }
  // Whether DomainExitStage has anything to do for a particle at x (a NaN coordinate is not
  // outside, as there).
  bool Outside(const Vec3& x) const {
    bool out = false;
    for (int d = 0; d < dim; ++d) out |= (x[d] < lo[d]) | (x[d] > hi[d]);
    return out;
  }
};

// The fast path of CheckStateStage, given J = det F: a sum of finite numbers is finite unless it
// overflows, and any NaN or Inf makes it non-finite, so a finite sum with J > 0 is a healthy
// particle; otherwise CheckStateStage's exact tests decide (an overflowing sum of finite values
// passes them).
inline bool SurelyHealthy(const Particles& P, size_t p, Real J) {
  const Real* t = P.stress[p].v;
  const Real sum = P.v[p].sum() + P.x[p].sum() + P.F[p].sum() + t[0] + t[1] + t[2] + t[3] + t[4] +
                   t[5];
  return std::isfinite(sum) && J > 0;
}

// Both tests over the particles a fused stress update has finished; `clean` stays true while
// every particle is inside the box and surely healthy. With `advect` (deferred advection, where
// the stress update is the last stage before AdvectStage), Test first moves the particle,
// x_{n+1} = x_n + dt v_{n+1} (Mast 2013 (2.16)), bitwise as AdvectParticles does.
struct EndChecks {
  DomainBox box;
  bool advect = false;
  Real dt = 0;
  bool clean = true;
  void Test(Particles& P, size_t p, Real J) {
    if (advect) P.x[p] = P.x[p] + dt * P.v[p];  // (2.16)
    clean &= !box.Outside(P.x[p]) & SurelyHealthy(P, p, J);
  }
};

}  // namespace surge

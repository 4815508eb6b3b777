// Artificial bulk viscosity (bulk_viscosity.h; docs/antilocking.md).
#include "stabilize/bulk_viscosity.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"

namespace surge {

bool AnyBulkViscosity(const Model& model) {
  return std::any_of(model.bulk_viscosity.begin(), model.bulk_viscosity.end(),
                     [](const BulkViscosity& b) { return b.enabled; });
}

void ComputeBulkViscosity(const Model& model, const StepContext& ctx,
                          const std::vector<MaterialGroup>& groups, const Particles& P,
                          const std::vector<Mat3>& L, BulkViscosityScratch& scratch) {
  const size_t n = P.size();
  scratch.q.assign(n, 0);
  scratch.id.assign(P.id.begin(), P.id.end());
  const Real l = ctx.dx;  // characteristic length: the cell size
  Real bound = 1e300;
  for (const MaterialGroup& g : groups) {
    const BulkViscosity& bv = model.bulk_viscosity[g.material];
    if (!bv.enabled || g.end == g.begin) continue;
    const Real c = WaveSpeed(model.materials[g.material]);  // elastic P-wave speed [m/s]
    std::array<Real, kReductionChunks> partial;
    partial.fill(1e300);
    ParallelChunks(g.end - g.begin, [&](size_t chunk, size_t b, size_t e) {
      Real dt_min = 1e300;
      for (size_t p = g.begin + b; p < g.begin + e; ++p) {
        const Real trd = L[p].trace();  // tr d = tr L: the volumetric strain rate [1/s]
        Real Q = bv.linear * c;         // LS-DYNA time step: Q = c1 c + c0 l |tr d| (compression)
        if (trd < 0) {
          const Real rho = P.mass[p] / (P.volume0[p] * Det3(P.F[p]));  // current density
          // von Neumann-Richtmyer quadratic + Landshoff linear term in the form of Wilkins (1980)
          // and the LS-DYNA Theory Manual ("Bulk viscosity"): q = rho l (c0 l trd^2 - c1 c trd).
          scratch.q[p] = rho * l * (bv.quadratic * l * trd * trd - bv.linear * c * trd);
          Q += bv.quadratic * l * (-trd);
        }
        dt_min = std::min(dt_min, l / (Q + std::sqrt(Q * Q + c * c) + P.v[p].norm()));
      }
      partial[chunk] = dt_min;
    });
    for (Real b : partial) bound = std::min(bound, b);
  }
  scratch.dt_bound = bound;
}

void ApplyBulkViscosity(Particles& P, BulkViscosityScratch& scratch) {
  const size_t n = P.size();
  // The particles may have been reordered (ReorderParticles) or some removed (DomainExit) since
  // q was computed: match by id when the order differs.
  if (!(scratch.id.size() == n && std::equal(scratch.id.begin(), scratch.id.end(), P.id.begin()))) {
    int64_t max_id = -1;
    for (int64_t id : scratch.id) max_id = std::max(max_id, id);
    scratch.by_id.assign(size_t(max_id + 1), 0);
    for (size_t k = 0; k < scratch.id.size(); ++k) scratch.by_id[size_t(scratch.id[k])] = scratch.q[k];
    scratch.q.assign(n, 0);
    for (size_t p = 0; p < n; ++p)
      if (P.id[p] >= 0 && P.id[p] <= max_id) scratch.q[p] = scratch.by_id[size_t(P.id[p])];
    scratch.id.assign(P.id.begin(), P.id.end());
  }
  scratch.saved.resize(n);
  ParallelFor(n, 1024, [&](size_t p) {
    if (scratch.q[p] == 0) return;
    scratch.saved[p] = P.stress[p];
    for (int d = 0; d < 3; ++d) P.stress[p].v[d] -= scratch.q[p];  // sigma - q 1 (tension positive)
  });
}

void RestoreStress(Particles& P, BulkViscosityScratch& scratch) {
  const size_t n = std::min(P.size(), scratch.q.size());
  ParallelFor(n, 1024, [&](size_t p) {
    if (scratch.q[p] != 0) P.stress[p] = scratch.saved[p];
  });
}

}  // namespace surge

// Particle reordering (DESIGN §5; spike note "What was slow" 3): every kReorderInterval steps the
// particles of each material group are permuted into block order, so that P2G and G2P stream
// through memory instead of gathering through the index table. The permutation depends only on
// positions and the current order, never on threads, so results stay bitwise reproducible; the
// interval is part of the reproducibility contract (it changes summation order).
#include <vector>

#include "core/parallel.h"

#include "step/stages.h"

namespace surge {
namespace {

template <class T>
void Permute(std::vector<T>& a, const std::vector<uint32_t>& order) {
  std::vector<T> permuted(a.size());
  ParallelFor(a.size(), 4096, [&](size_t i) { permuted[i] = a[order[i]]; });
  a.swap(permuted);
}

void Permute(HistoryArray& a, const std::vector<uint32_t>& order) {
  const size_t stride = size_t(a.stride());
  std::vector<Real> permuted(a.size() * stride);
  ParallelFor(a.size(), 4096, [&](size_t i) {
    const Real* from = a[order[i]];
    for (size_t k = 0; k < stride; ++k) permuted[i * stride + k] = from[k];
  });
  a.Swap(permuted);
}

}  // namespace

void ReorderParticlesStage(const Model&, const StepContext&, State& s, Workspace& w, StepReport&) {
  if (s.step % kReorderInterval != 0) return;
  Particles& P = s.particles;
  SparseGrid& grid = w.grid;
  const size_t n = P.size();
  if (n == 0) return;
  // New order: for each group, its particles in block order (grid.sorted is stable by index).
  std::vector<uint32_t>& order = w.reorder;
  order.resize(n);
  std::vector<size_t> cursor(s.groups.size());
  for (size_t g = 0; g < s.groups.size(); ++g) cursor[g] = s.groups[g].begin;
  bool identity = true;
  for (uint32_t p : grid.sorted) {
    size_t g = 0;
    while (p >= s.groups[g].end) ++g;
    identity &= cursor[g] == p;
    order[cursor[g]++] = p;
  }
  if (identity) return;
  // Apply new[i] = old[order[i]] array by array: a parallel gather into a fresh array that then
  // replaces the old one. It streams each array once and holds one extra array at a time (the
  // serial cycle-following Move it replaces touched all 14 arrays per particle, on one thread).
  static_assert(sizeof(Particles) == kParticlesSize,
                "a new Particles array must be permuted here too");
  for (auto* a : {&P.x, &P.v, &P.ext_force}) Permute(*a, order);
  for (auto* a : {&P.C, &P.F, &P.strain}) Permute(*a, order);
  for (auto* a : {&P.stress, &P.elastic_b}) Permute(*a, order);
  for (auto* a : {&P.mass, &P.volume0}) Permute(*a, order);
  for (auto* a : {&P.material, &P.body}) Permute(*a, order);
  Permute(P.history, order);
  Permute(P.id, order);
  // The grid binning follows the particles.
  std::vector<int32_t>& block = grid.particle_block;
  std::vector<int32_t> old_block(block);
  for (size_t i = 0; i < n; ++i) block[i] = old_block[order[i]];
  BinParticles(grid);
}

}  // namespace surge

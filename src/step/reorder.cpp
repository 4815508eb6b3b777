// Particle reordering (DESIGN §5; spike note "What was slow" 3): every kReorderInterval steps the
// particles of each material group are permuted into block order, so that P2G and G2P stream
// through memory instead of gathering through the index table. The permutation depends only on
// positions and the current order, never on threads, so results stay bitwise reproducible; the
// interval is part of the reproducibility contract (it changes summation order).
#include <vector>

#include "step/stages.h"

namespace surge {

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
  // Apply new[i] = old[order[i]] in place by following cycles, with slot n as the temporary.
  std::vector<uint8_t>& done = w.exit_flag;
  done.assign(n, 0);
  P.Resize(n + 1);
  for (size_t start = 0; start < n; ++start) {
    if (done[start] || order[start] == start) continue;
    P.Move(n, start);
    size_t j = start;
    while (true) {
      done[j] = 1;
      const size_t k = order[j];
      if (k == start) {
        P.Move(j, n);
        break;
      }
      P.Move(j, k);
      j = k;
    }
  }
  P.Resize(n);
  // The grid binning follows the particles.
  std::vector<int32_t>& block = grid.particle_block;
  std::vector<int32_t> old_block(block);
  for (size_t i = 0; i < n; ++i) block[i] = old_block[order[i]];
  BinParticles(grid);
}

}  // namespace surge

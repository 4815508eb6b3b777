// Owner-consistent parallel loops over the grid's blocks and particle runs.
//
// On the 2-vCPU VMs this project runs on, a cache line moves from one core to the other in about
// 210 ns (a ping-pong of one line: 420 ns round trip), so a stage that reads or overwrites what
// the other core wrote in the stage before pays for every line. Measured (elastic column, 1e4
// particles, 2 threads): G2P run entirely on one thread costs 271 ns per particle inside a
// 2-thread step against 139 ns in a 1-thread step, because about half the particle and grid
// lines it touches were last written by the other core in P2G, the grid update or the last G2P.
//
// The loops here cut their items at the same particle positions n t / T (T = WorkerThreads())
// and run part t with tbb::static_partitioner, which hands part t to the same arena slot in every
// loop: a thread keeps the same particles and the blocks that hold them from stage to stage and
// from step to step (ParallelChunks cuts the particle index space the same way). Particles are
// in block order (ReorderParticlesStage), so the particles of the blocks in part t are about
// [n t / T, n (t + 1) / T). What an item computes does not depend on the part it falls in: results
// stay bitwise the same for any thread count.
#pragma once
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "grid/sparse_grid.h"

namespace surge {

// First block of part t of T: the first block whose particles start at or after n t / T.
inline size_t OwnedBlockBegin(const SparseGrid& grid, size_t t, size_t parts) {
  const size_t nb = grid.block_count();
  if (t == 0) return 0;
  if (t >= parts) return nb;
  const size_t n = grid.block_begin.empty() ? 0 : grid.block_begin[nb];
  const size_t at = n * t / parts;
  // block_begin is non-decreasing: the first b with block_begin[b] >= at.
  return size_t(std::lower_bound(grid.block_begin.begin(), grid.block_begin.begin() + ptrdiff_t(nb),
                                 uint32_t(at)) -
                grid.block_begin.begin());
}

// First run of part t of T (runs are in block order).
inline size_t OwnedRunBegin(const SparseGrid& grid, size_t t, size_t parts) {
  if (t == 0) return 0;
  if (t >= parts) return grid.runs.size();
  const size_t nb = grid.block_count();
  const size_t n = grid.block_begin.empty() ? 0 : grid.block_begin[nb];
  const uint32_t at = uint32_t(n * t / parts);
  return size_t(std::lower_bound(grid.runs.begin(), grid.runs.end(), at,
                                 [](const SparseGrid::ParticleRun& r, uint32_t v) {
                                   return r.begin < v;
                                 }) -
                grid.runs.begin());
}

// Runs f(t) for each part t in [0, parts), part t on the same thread in every call.
template <typename F>
void ForEachPart(size_t parts, const F& f) {
  if (parts <= 1) {
    f(size_t{0});
    return;
  }
  ParallelForStatic(parts, f);
}

// f(b) for every block b, each on the thread that owns b's particles.
template <typename F>
void ForOwnedBlocks(const SparseGrid& grid, const F& f) {
  const size_t parts = WorkerThreads();
  ForEachPart(parts, [&](size_t t) {
    const size_t end = OwnedBlockBegin(grid, t + 1, parts);
    for (size_t b = OwnedBlockBegin(grid, t, parts); b < end; ++b) f(b);
  });
}

// f(r) for every particle run r (SparseGrid::runs), each on the thread that owns its particles.
template <typename F>
void ForOwnedRuns(const SparseGrid& grid, const F& f) {
  const size_t parts = WorkerThreads();
  ForEachPart(parts, [&](size_t t) {
    const size_t end = OwnedRunBegin(grid, t + 1, parts);
    for (size_t r = OwnedRunBegin(grid, t, parts); r < end; ++r) f(r);
  });
}

// The colour of a block: the parity of its block coordinate (BuildTopology's grid.colour).
inline int BlockColour(const SparseGrid& grid, size_t b) {
  const Vec3i bc = grid.block_origin[b] / kBlockDim;
  return (bc.x() & 1) | ((bc.y() & 1) << 1) | ((bc.z() & 1) << 2);
}

// Calls f(a, b, c) for the padded nodes of a block (BlockPad `Pad`: E x E x Ez) that lie in its
// upper neighbour o (o = ox + 2 oy + 4 oz, grid.neighbor[block][o]).
template <class Pad, class F>
void ForPaddedNodesIn(int o, const F& f) {
  const int a0 = (o & 1) ? kBlockDim : 0, a1 = (o & 1) ? Pad::E : kBlockDim;
  const int b0 = (o & 2) ? kBlockDim : 0, b1 = (o & 2) ? Pad::E : kBlockDim;
  const int c0 = (o & 4) ? kBlockDim : 0, c1 = (o & 4) ? Pad::Ez : std::min(kBlockDim, Pad::Ez);
  for (int a = a0; a < a1; ++a)
    for (int b = b0; b < b1; ++b)
      for (int c = c0; c < c1; ++c) f(a, b, c);
}

// A block scatter (P2G and the anti-locking and shifting sums) with every block on the thread
// that owns its particles and no barrier per colour. Each block accumulates into a padded buffer
// that reaches into itself and its 7 upper neighbours, and every node must receive the blocks'
// sums in colour order, the order of the colour-phased loops (one thread runs those), so that the
// result is bitwise the same for any thread count. The writers of a target block X are the blocks
// X - o, o in {0,1}^3, one per colour.
//   accumulate(b, buf): fill buf (a Buffer) with block b's sums;
//   add(b, buf, o): add the part of b's buffer in its upper neighbour o into the grid.
// Only blocks with particles (grid.block_begin) are visited. On more than one thread, one of two
// schedules, which give the same sums bitwise:
// - Few blocks (at most kTwoPhaseBlocksPerThread per thread with particles, e.g. a 1e4-particle
//   column's 36 blocks on 2 threads): every thread accumulates its own blocks into buffers kept
//   per block, then, after one barrier, adds into each target block it owns the buffers of X's
//   writers in colour order. Nothing waits on a single block, which the colour chains below do
//   when a handful of blocks per colour are split over the threads. With more blocks the buffers
//   (64 KB a block for P2G in 3-D) no longer stay in cache between the two phases: a
//   1e5-particle column (96 blocks) ran P2G 5-12 % slower this way (docs/benchmarks.md). The
//   buffers are numbered by the blocks with particles, so at most that limit of them is kept.
// - Otherwise: a block adds its sums into X once every writer of X of a lower colour has
//   (`written[X]`: one bit per colour, release/acquire). A thread takes its blocks colour by
//   colour; where it must wait on a writer no thread has started, it runs that block itself, into
//   a buffer one level deeper: each wait is on a strictly lower colour, so this ends (at most 8
//   levels) and cannot deadlock, even when one thread runs every part.
inline constexpr size_t kTwoPhaseBlocksPerThread = 24;

template <class Buffer, class Accumulate, class Add>
void OrderedBlockScatter(const SparseGrid& grid, int dim, const Accumulate& accumulate,
                         const Add& add) {
  const size_t nb = grid.block_count();
  const int targets = dim == 3 ? 8 : 4;  // a 2-D block has no node plane above z = 0
  const auto has_particles = [&](size_t b) { return grid.block_begin[b + 1] > grid.block_begin[b]; };
  const size_t parts = WorkerThreads();
  if (parts <= 1) {  // the colour-phased order itself
    thread_local Buffer buf;
    for (int colour = 0; colour < 8; ++colour)
      for (int32_t b : grid.colour[colour]) {
        if (!has_particles(size_t(b))) continue;
        accumulate(size_t(b), buf);
        for (int o = 0; o < targets; ++o)
          if (grid.neighbor[size_t(b)][o] >= 0) add(size_t(b), buf, o);
      }
    return;
  }
  // Scratch kept between calls (no allocation per step once grown): [X][colour], the block
  // writing X or -1, and its neighbour index o; the colours writing X; the colours added into X;
  // state 1: claimed; the two-phase buffers and each block's buffer (its rank among the blocks
  // with particles). Named through plain references: a thread_local
  // named inside the lambdas below would be the worker thread's own copy.
  thread_local std::vector<std::array<int32_t, 8>> writer_scratch;
  thread_local std::vector<std::array<int8_t, 8>> writer_o_scratch;
  thread_local std::vector<uint8_t> writers_scratch, written_scratch, state_scratch;
  thread_local std::vector<Buffer> block_buffer_scratch;
  thread_local std::vector<uint32_t> slot_scratch;
  auto& writer = writer_scratch;
  auto& writer_o = writer_o_scratch;
  auto& writers = writers_scratch;
  auto& written = written_scratch;
  auto& state = state_scratch;
  auto& slot = slot_scratch;
  std::array<int32_t, 8> none;
  none.fill(-1);
  writer.assign(nb, none);
  writer_o.resize(nb);
  writers.assign(nb, 0);
  slot.resize(nb);
  size_t blocks_with_particles = 0;
  for (size_t b = 0; b < nb; ++b) {
    if (!has_particles(b)) continue;
    slot[b] = uint32_t(blocks_with_particles++);
    const int c = BlockColour(grid, b);
    for (int o = 0; o < targets; ++o) {
      const int32_t x = grid.neighbor[b][o];
      if (x < 0) continue;
      writer[size_t(x)][c] = int32_t(b);
      writer_o[size_t(x)][c] = int8_t(o);
      writers[size_t(x)] |= uint8_t(1u << c);
    }
  }
  if (blocks_with_particles <= kTwoPhaseBlocksPerThread * parts) {
    auto& buffers = block_buffer_scratch;
    if (buffers.size() < blocks_with_particles) buffers.resize(blocks_with_particles);
    ForEachPart(parts, [&](size_t t) {
      const size_t end = OwnedBlockBegin(grid, t + 1, parts);
      for (size_t b = OwnedBlockBegin(grid, t, parts); b < end; ++b)
        if (has_particles(b)) accumulate(b, buffers[slot[b]]);
    });
    ForEachPart(parts, [&](size_t t) {  // each target's writers in colour order
      const size_t end = OwnedBlockBegin(grid, t + 1, parts);
      for (size_t x = OwnedBlockBegin(grid, t, parts); x < end; ++x)
        for (uint8_t cs = writers[x]; cs != 0; cs &= uint8_t(cs - 1)) {
          const int c = std::countr_zero(unsigned(cs));
          const size_t b = size_t(writer[x][c]);
          add(b, buffers[slot[b]], writer_o[x][c]);
        }
    });
    return;
  }
  written.assign(nb, 0);
  state.assign(nb, 0);
  const auto run = [&](const auto& self, size_t b, int level) -> void {
    thread_local std::array<Buffer, 8> levels;  // the running thread's, one per nesting level
    Buffer& buf = levels[size_t(level)];
    accumulate(b, buf);
    const int c = BlockColour(grid, b);
    const uint8_t lower = uint8_t((1u << c) - 1);
    for (int o = 0; o < targets; ++o) {
      const int32_t x = grid.neighbor[b][o];
      if (x < 0) continue;
      const uint8_t need = writers[size_t(x)] & lower;
      std::atomic_ref<uint8_t> done(written[size_t(x)]);
      for (uint8_t have; ((have = done.load(std::memory_order_acquire)) & need) != need;) {
        const int first = std::countr_zero(unsigned(need & ~have));  // lowest colour missing
        const size_t w = size_t(writer[size_t(x)][first]);
        uint8_t free = 0;
        if (std::atomic_ref<uint8_t>(state[w]).compare_exchange_strong(free, 1))
          self(self, w, level + 1);  // nobody has started it: run it here
        else
          std::this_thread::yield();  // another thread is adding it now
      }
      add(b, buf, o);
      done.fetch_or(uint8_t(1u << c), std::memory_order_release);
    }
  };
  ForEachPart(parts, [&](size_t t) {
    const int32_t lo = int32_t(OwnedBlockBegin(grid, t, parts));
    const int32_t hi = int32_t(OwnedBlockBegin(grid, t + 1, parts));
    for (int colour = 0; colour < 8; ++colour) {
      const auto& blocks = grid.colour[colour];
      for (auto it = std::lower_bound(blocks.begin(), blocks.end(), lo);
           it != blocks.end() && *it < hi; ++it) {
        const size_t b = size_t(*it);
        uint8_t free = 0;
        if (!has_particles(b) || !std::atomic_ref<uint8_t>(state[b]).compare_exchange_strong(free, 1))
          continue;  // empty, or already run by a thread that waited on it
        run(run, b, 0);
      }
    }
  });
}

}  // namespace surge

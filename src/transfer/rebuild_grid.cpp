// Grid topology and particle binning, every step (DESIGN §5; spike note "Design as tested" 1-4).
#include <algorithm>
#include <array>

#include "core/parallel.h"
#include "core/simd.h"
#include "transfer/dispatch.h"
#include "transfer/owned_loops.h"
#include "transfer/transfer.h"
#include "transfer/walls.h"

namespace surge {
namespace {

// Block coordinate of the block owning the stencil base node of x, and the mask of the axes along
// which the stencil crosses into the next block.
template <int kDim, class K>
Vec3i OwnerBlock(const Vec3& x, Real inv_dx, uint8_t& mask) {
  Vec3i block(0, 0, 0);
  mask = 0;
  for (int d = 0; d < kDim; ++d) {
    const int base = K::Base(x[d] * inv_dx);
    block[d] = base >> kBlockBits;  // arithmetic shift = floor division (C++20)
    const int local = base - (block[d] << kBlockBits);
    if (local + K::kWidth - 1 >= kBlockDim) mask |= uint8_t(1u << d);
  }
  return block;
}

// Pass 1 over particles [begin, end) of one chunk: owner block and crossing mask of every
// particle; the chunk's deduplicated requests. Each particle's particle_block holds, for now, the
// index of its request within its chunk's list. The same pass marks the walls the particles touch
// (the gap test, WallTouchMarker).
template <int kDim, class K>
[[gnu::always_inline]] inline void RequestsOfChunkImpl(const Particles& particles, Real inv_dx,
                                                       const WallTouchMarker& walls,
                                                       SparseGrid& grid, size_t chunk,
                                                       size_t begin, size_t end) {
  auto& out = grid.chunk_requests[chunk];
  out.clear();
  // Direct-mapped cache of recent (block, mask) entries (spike note: "dedupe quality").
  constexpr int kCache = 64;
  BlockRequest cache[kCache];
  int32_t cache_index[kCache];
  bool used[kCache] = {};
  BlockRequest last;
  int32_t last_index = -1;
  WallTouchMarker::Recent recent;
  const WallTouchMarker::Near near = walls.near();  // a local copy: kept in registers
  const bool mark = walls.active();
  for (size_t p = begin; p < end; ++p) {
    uint8_t mask = 0;
    const Vec3i block = OwnerBlock<kDim, K>(particles.x[p], inv_dx, mask);
    if (last_index < 0 || !(last.block == block && last.upper == mask)) {
      last = BlockRequest{block, mask};
      const unsigned h = (unsigned(block.x()) * 73856093u ^ unsigned(block.y()) * 19349663u ^
                          unsigned(block.z()) * 83492791u ^ mask) % kCache;
      if (used[h] && cache[h].block == block && cache[h].upper == mask) {
        last_index = cache_index[h];
      } else {
        used[h] = true;
        cache[h] = last;
        last_index = cache_index[h] = int32_t(out.size());
        out.push_back(last);
      }
    }
    grid.particle_block[p] = last_index;
    if (mark && near.MayTouch(particles.x[p], particles.volume0[p]))
      walls.MarkTouched(particles.x[p], particles.volume0[p], recent);
  }
}

template <int kDim, class K>
void RequestsOfChunk(const Particles& particles, Real inv_dx, const WallTouchMarker& walls,
                     SparseGrid& grid, size_t chunk, size_t begin, size_t end) {
  RequestsOfChunkImpl<kDim, K>(particles, inv_dx, walls, grid, chunk, begin, end);
}
#if SURGE_HAVE_WIDE_SIMD
// The same pass compiled for AVX, whose SSE4.1 `roundsd` takes the three floors of OwnerBlock in
// one instruction each (the portable build emulates floor in about ten).
template <int kDim, class K>
SURGE_TARGET_WIDE void RequestsOfChunkWide(const Particles& particles, Real inv_dx,
                                           const WallTouchMarker& walls, SparseGrid& grid,
                                           size_t chunk, size_t begin, size_t end) {
  RequestsOfChunkImpl<kDim, K>(particles, inv_dx, walls, grid, chunk, begin, end);
}
#endif

template <int kDim, class K>
void ComputeRequests(const Particles& particles, Real inv_dx, const WallTouchMarker& walls,
                     SparseGrid& grid) {
  const size_t n = particles.size();
  grid.chunk_requests.resize(kReductionChunks);
  grid.particle_block.resize(n);
  [[maybe_unused]] const bool wide = WideSimd();
  ParallelChunks(n, [&](size_t chunk, size_t begin, size_t end) {
#if SURGE_HAVE_WIDE_SIMD
    if (wide)
      return RequestsOfChunkWide<kDim, K>(particles, inv_dx, walls, grid, chunk, begin, end);
#endif
    RequestsOfChunk<kDim, K>(particles, inv_dx, walls, grid, chunk, begin, end);
  });
  grid.requests.clear();
  for (const auto& c : grid.chunk_requests) grid.requests.insert(grid.requests.end(), c.begin(), c.end());
}

// Pass 2, after the topology is built: the index of every particle's owner block, through its
// request (every requested block exists; BuildTopology gives their indices), so that no
// particle's block is computed twice.
void FindOwnerBlocks(SparseGrid& grid) {
  std::array<size_t, kReductionChunks + 1> offset{};
  for (size_t c = 0; c < kReductionChunks; ++c)
    offset[c + 1] = offset[c] + grid.chunk_requests[c].size();
  ParallelChunks(grid.particle_block.size(), [&](size_t chunk, size_t begin, size_t end) {
    const int32_t* to_block = grid.request_block.data() + offset[chunk];
    for (size_t p = begin; p < end; ++p) grid.particle_block[p] = to_block[grid.particle_block[p]];
  });
}

// BinParticles' stable counting sort in parallel over the fixed particle chunks: each chunk
// counts its particles per block, the chunks' cursors are laid out block by block and, within a
// block, chunk by chunk (particle order), and each chunk then places its particles. The order is
// that of the serial sort, for any thread count.
void BinInChunks(SparseGrid& grid) {
  const size_t n = grid.particle_block.size();
  const size_t nb = grid.block_count();
  std::vector<uint32_t>& cursor = grid.chunk_cursor;  // [chunk * nb + block]
  cursor.resize(kReductionChunks * nb);
  ParallelChunks(n, [&](size_t c, size_t begin, size_t end) {
    uint32_t* count = cursor.data() + c * nb;
    std::fill(count, count + nb, 0u);
    for (size_t p = begin; p < end; ++p) ++count[grid.particle_block[p]];
  });
  grid.block_begin.resize(nb + 1);
  uint32_t next = 0;
  for (size_t b = 0; b < nb; ++b) {
    grid.block_begin[b] = next;
    for (size_t c = 0; c < kReductionChunks; ++c) {
      const uint32_t count = cursor[c * nb + b];
      cursor[c * nb + b] = next;
      next += count;
    }
  }
  grid.block_begin[nb] = next;
  ParallelChunks(n, [&](size_t c, size_t begin, size_t end) {
    uint32_t* at = cursor.data() + c * nb;
    for (size_t p = begin; p < end; ++p) grid.sorted[at[grid.particle_block[p]]++] = uint32_t(p);
  });
}

}  // namespace

void RebuildGrid(const Model& model, const Particles& particles, SparseGrid& grid) {
  const Real inv_dx = 1.0 / model.dx;
  grid.SetDimension(model.dim);  // 2-D blocks hold only their z = 0 node plane
  grid.keep_reaction = !model.sensors.empty();  // the nodal reaction is read by sensors only
  const WallTouchMarker walls(model, model.dx, grid);  // clears the maps; marks in pass 1
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    ComputeRequests<kDim, K>(particles, inv_dx, walls, grid);
  });
  BuildTopology(grid.requests, grid);

  FindOwnerBlocks(grid);

  BinParticles(grid);
  // The P2G sums start at zero, cleared block by block by the thread that then adds the block's
  // particles into them (a serial clear of 56 bytes per node was a tenth of a small run's grid
  // rebuild).
  const size_t per_block = size_t(grid.block_nodes);
  ForOwnedBlocks(grid, [&](size_t b) {
    const ptrdiff_t begin = ptrdiff_t(b * per_block), end = ptrdiff_t((b + 1) * per_block);
    std::fill(grid.mass.begin() + begin, grid.mass.begin() + end, 0.0);
    std::fill(grid.momentum.begin() + begin, grid.momentum.begin() + end, Vec3::Zero());
    std::fill(grid.force.begin() + begin, grid.force.begin() + end, Vec3::Zero());
  });
}

void BinParticles(SparseGrid& grid) {
  // Stable counting sort by owner block: order inside a block is particle order, so node sums
  // are independent of the thread count (spike note, "Determinism").
  const size_t n = grid.particle_block.size();
  const size_t nb = grid.block_count();
  grid.sorted.resize(n);
  if (kReductionChunks * nb > n / 4) {
    // More than n / 256 blocks (sparse or small runs): the per-chunk tables would cost more than
    // they save. The serial sort, the same order; the cursors are one per block.
    std::vector<uint32_t>& cursor = grid.chunk_cursor;
    grid.block_begin.assign(nb + 1, 0);
    for (size_t p = 0; p < n; ++p) ++grid.block_begin[grid.particle_block[p] + 1];
    for (size_t b = 0; b < nb; ++b) grid.block_begin[b + 1] += grid.block_begin[b];
    cursor.assign(grid.block_begin.begin(), grid.block_begin.end() - 1);
    for (size_t p = 0; p < n; ++p) grid.sorted[cursor[grid.particle_block[p]]++] = uint32_t(p);
  } else {
    BinInChunks(grid);
  }

  // Gather work items: one run per non-empty block, cut into runs of at most n / 16 particles
  // (never below 256: each run gathers its block's node halo once), so that up to 4 threads
  // each get about 4 runs. The cut depends on the particles only, not on the thread count:
  // the fused stress update sums its stress power per run (GridToParticleStressStage).
  const size_t cap = std::max<size_t>(256, n / 16 + 1);
  grid.runs.clear();
  for (size_t b = 0; b < nb; ++b) {
    const uint32_t begin = grid.block_begin[b], count = grid.block_begin[b + 1] - begin;
    if (count == 0) continue;
    const uint32_t pieces = uint32_t((count + cap - 1) / cap);
    for (uint32_t i = 0; i < pieces; ++i)
      grid.runs.push_back({uint32_t(b), begin + uint32_t(uint64_t(count) * i / pieces),
                           begin + uint32_t(uint64_t(count) * (i + 1) / pieces)});
  }
}

}  // namespace surge

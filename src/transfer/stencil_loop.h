// Shared machinery of the block-local transfers: padded per-block buffers covering a block and
// the first W-1 nodes of its upper neighbours (spike note, "Design as tested" 5 and 7).
#pragma once
#include <type_traits>
#include <vector>

#include "grid/sparse_grid.h"
#include "transfer/shape_functions.h"

namespace surge {

template <int kDim, class K>
struct BlockPad {
  static constexpr int E = kBlockDim + K::kWidth - 1;  // padded extent along x and y
  static constexpr int Ez = kDim == 3 ? E : 1;         // along z (1 in 2-D)
  static constexpr int kSize = E * E * Ez;
  static constexpr int Index(int a, int b, int c) { return (a * E + b) * Ez + c; }
};

// Grid index (block * block_nodes + local) of padded node (a,b,c) of block `block`, or -1 when the
// neighbour block that holds it is not active.
inline long PaddedToGrid(const SparseGrid& grid, size_t block, int a, int b, int c) {
  const int o = (a >= kBlockDim) | ((b >= kBlockDim) << 1) | ((c >= kBlockDim) << 2);
  const int32_t nb = grid.neighbor[block][o];
  if (nb < 0) return -1;
  return long(nb) * grid.block_nodes +
         grid.Local(a & (kBlockDim - 1), b & (kBlockDim - 1), c & (kBlockDim - 1));
}

// GIMP half-width of a particle (cell units); 0 for the other kernels.
template <class K>
inline Real KernelHalfWidth(int dim, Real volume0, Real inv_dx) {
  if constexpr (std::is_same_v<K, GimpKernel>) return GimpHalfWidth(dim, volume0, inv_dx);
  return 0.0;
}

}  // namespace surge

// Small queries on the sparse grid that need no OpenVDB.
#include "grid/sparse_grid.h"

namespace surge {

size_t SparseGrid::ActiveNodeCount() const {
  size_t count = 0;
  for (Real m : mass) count += m > 0;
  return count;
}

}  // namespace surge

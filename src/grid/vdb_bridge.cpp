// The only includer of OpenVDB (STYLE H.10): block topology as an Int32Tree whose leaves are the
// 8^3 blocks, the block/neighbour tables, and .vdb export of grid fields.
// Scheme measured in shared/notes/vdb-block-grid-spike.md: deduplicated leaf-level inserts, voxel 0
// of each leaf holds the dense block index; the tree is rebuilt every step.
#include <openvdb/openvdb.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>
#include <vector>

#include "grid/sparse_grid.h"

namespace surge {

class BlockTopology {
 public:
  openvdb::Int32Tree tree{-1};
  std::vector<openvdb::Coord> wanted, dropped;  // scratch of BuildTopology
  size_t stale = 0;  // leaves deleted since the tree was last cleared
  // The requests the block tables were last built or kept for (`built`: they hold a
  // topology): unchanged requests, or requests that need the same leaves, keep the tables as
  // they are (BuildTopology).
  std::vector<BlockRequest> last_requests;
  std::vector<uint8_t> needed;  // scratch of RequestsNeedTheBuiltLeaves: per block
  bool built = false;
};

namespace {

void InitOpenVdbOnce() {
  static std::once_flag flag;
  std::call_once(flag, [] { openvdb::initialize(); });
}

static_assert(openvdb::Int32Tree::LeafNodeType::DIM == kBlockDim,
              "OpenVDB leaf edge must equal the block edge");

openvdb::Coord ToCoord(const Vec3i& node) { return openvdb::Coord(node.x(), node.y(), node.z()); }

}  // namespace

SparseGrid::SparseGrid() : topology(std::make_unique<BlockTopology>()) {}
SparseGrid::~SparseGrid() = default;
SparseGrid::SparseGrid(SparseGrid&&) noexcept = default;
SparseGrid& SparseGrid::operator=(SparseGrid&&) noexcept = default;

namespace {

// The leaves the requests need, in topo.wanted: each request's owner leaf and its upper
// neighbours in every subset of its crossing mask, sorted and unique.
void BuildLeafSet(const std::vector<BlockRequest>& requests, BlockTopology& topo) {
  std::vector<openvdb::Coord>& wanted = topo.wanted;
  wanted.clear();
  for (const BlockRequest& r : requests) {
    const Vec3i origin = r.block * kBlockDim;
    for (int o = 0; o < 8; ++o) {
      if ((o & ~r.upper) != 0) continue;  // only subsets of the crossing mask
      wanted.push_back(ToCoord(origin + kBlockDim * Vec3i(o & 1, (o >> 1) & 1, (o >> 2) & 1)));
    }
  }
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
}

// grid.request_block: the index of each request's owner block in the tables (-1: none).
void LookupRequestBlocks(const std::vector<BlockRequest>& requests, SparseGrid& grid) {
  std::vector<Vec3i>& blocks = grid.request_blocks;
  blocks.resize(requests.size());
  for (size_t r = 0; r < blocks.size(); ++r) blocks[r] = requests[r].block;
  grid.request_block.resize(blocks.size());
  LookupBlocks(grid, blocks.data(), blocks.size(), grid.request_block.data());
}

// Whether the requests need exactly the leaves of the tables built before (topo.built): each
// request's owner block and its upper neighbours in every subset of its crossing mask are
// blocks of the tables, and together they are all of them. Looks the requests up on the way
// (LookupRequestBlocks). Against sorting the leaf set (BuildLeafSet) and comparing it, this
// walks the neighbour table: 4-8 us against 25 us a step on a 1e4-particle water column, whose
// requests change on most steps while its blocks do not.
bool RequestsNeedTheBuiltLeaves(const std::vector<BlockRequest>& requests, BlockTopology& topo,
                                SparseGrid& grid) {
  if (!topo.built) return false;
  LookupRequestBlocks(requests, grid);
  std::vector<uint8_t>& needed = topo.needed;
  needed.assign(grid.block_count(), 0);
  size_t count = 0;
  for (size_t r = 0; r < requests.size(); ++r) {
    const int32_t b = grid.request_block[r];
    if (b < 0) return false;
    for (int o = 0; o < 8; ++o) {
      if ((o & ~requests[r].upper) != 0) continue;  // only subsets of the crossing mask
      const int32_t x = grid.neighbor[size_t(b)][o];
      if (x < 0) return false;
      count += needed[size_t(x)] == 0 ? 1 : 0;
      needed[size_t(x)] = 1;
    }
  }
  return count == grid.block_count();
}

// The tree's leaves set to topo.wanted, numbered in tree order, and the block tables: origins,
// upper neighbours, colours.
void BuildBlockTables(BlockTopology& topo, SparseGrid& grid) {
  auto& tree = topo.tree;
  const std::vector<openvdb::Coord>& wanted = topo.wanted;
  // The tree's internal nodes are kept from step to step and only the leaves that are no longer
  // needed are deleted: clearing the tree freed its internal nodes (32^3 and 16^3 child tables),
  // and allocating them again was most of a small run's grid rebuild (1e4 particles: 0.22 of
  // 0.41 ms). The leaves are numbered in tree order below, which depends only on the set of
  // leaves, not on the tree's history. The tree is cleared once the leaves deleted since the last
  // clear outnumber four times those in use, so that the internal nodes a flow has left behind do
  // not pile up.
  if (topo.stale > 4 * wanted.size() + 64) {
    tree.clear();
    topo.stale = 0;
  }
  topo.dropped.clear();
  for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf)
    if (!std::binary_search(wanted.begin(), wanted.end(), leaf->origin()))
      topo.dropped.push_back(leaf->origin());
  for (const openvdb::Coord& c : topo.dropped)
    delete tree.stealNode<openvdb::Int32Tree::LeafNodeType>(c, -1, false);
  topo.stale += topo.dropped.size();
  {
    openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(tree);
    for (const openvdb::Coord& c : wanted) acc.touchLeaf(c);
  }
  // Number the leaves in tree order; voxel 0 holds the index.
  const size_t count = tree.leafCount();
  grid.block_origin.resize(count);
  int32_t index = 0;
  for (auto leaf = tree.beginLeaf(); leaf; ++leaf) {
    const openvdb::Coord o = leaf->origin();
    grid.block_origin[index] = Vec3i(o.x(), o.y(), o.z());
    leaf->setValueOn(0, index);
    ++index;
  }
  grid.neighbor.resize(count);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 64), [&](const tbb::blocked_range<size_t>& r) {
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> acc(tree);
    for (size_t b = r.begin(); b != r.end(); ++b) {
      for (int o = 0; o < 8; ++o) {
        const Vec3i n = grid.block_origin[b] + kBlockDim * Vec3i(o & 1, (o >> 1) & 1, (o >> 2) & 1);
        const auto* leaf = acc.probeConstLeaf(ToCoord(n));
        grid.neighbor[b][o] = leaf ? leaf->getValue(0) : -1;
      }
    }
  });
  for (auto& c : grid.colour) c.clear();
  for (size_t b = 0; b < count; ++b) {
    const Vec3i bc = grid.block_origin[b] / kBlockDim;
    const int c = (bc.x() & 1) | ((bc.y() & 1) << 1) | ((bc.z() & 1) << 2);
    grid.colour[c].push_back(static_cast<int32_t>(b));
  }
  topo.built = true;
}

// The node arrays sized to the blocks (SparseGrid::SetDimension gives the nodes per block).
void SizeNodeArrays(SparseGrid& grid) {
  const size_t nodes = grid.block_count() * size_t(grid.block_nodes);
  // The P2G sums are cleared after the particles are binned, by the thread that owns each block
  // (ClearNodeSums, transfer/owned_loops.h).
  grid.mass.resize(nodes);
  // momentum and velocity share a buffer (SparseGrid::momentum): take it back from velocity.
  if (grid.momentum.empty()) grid.momentum.swap(grid.velocity);
  grid.momentum.resize(nodes);
  grid.force.resize(nodes);
  grid.velocity_new.resize(nodes);
  if (grid.keep_reaction) grid.reaction.resize(nodes);
  else grid.reaction = {};
}

}  // namespace

void BuildTopology(const std::vector<BlockRequest>& requests, SparseGrid& grid) {
  InitOpenVdbOnce();
  if (!grid.topology) grid.topology = std::make_unique<BlockTopology>();
  BlockTopology& topo = *grid.topology;
  // Blocks change only when a particle enters a new one or reaches across a block face: on most
  // steps the requests, or else the leaf set they give, are those of the last step, and the
  // numbering, neighbours and colours (which depend on the leaf set alone) are kept. Measured on
  // a 1e4-particle water column: 70 us of a 3.5 ms step on one thread, serial on two
  // (docs/benchmarks.md, twenty-fourth increment). With the same requests, the requests' blocks
  // (grid.request_block) are those of the last call too.
  const bool same_requests =
      topo.built && requests.size() == topo.last_requests.size() &&
      std::equal(requests.begin(), requests.end(), topo.last_requests.begin(),
                 [](const BlockRequest& a, const BlockRequest& b) {
                   return a.block == b.block && a.upper == b.upper;
                 });
  if (!same_requests) {
    topo.last_requests = requests;
    if (!RequestsNeedTheBuiltLeaves(requests, topo, grid)) {
      BuildLeafSet(requests, topo);
      BuildBlockTables(topo, grid);
      LookupRequestBlocks(requests, grid);
    }
  }
  SizeNodeArrays(grid);
}

void LookupBlocks(const SparseGrid& grid, const Vec3i* blocks, size_t n, int32_t* out) {
  const auto& tree = grid.topology->tree;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
    openvdb::tree::ValueAccessor<const openvdb::Int32Tree> acc(tree);
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const auto* leaf = acc.probeConstLeaf(ToCoord(blocks[i] * kBlockDim));
      out[i] = leaf ? leaf->getValue(0) : -1;
    }
  });
}

void ExportGridVdb(const SparseGrid& grid, Real dx, const std::string& path) {
  InitOpenVdbOnce();
  auto mass = openvdb::FloatGrid::create(0.0f);
  auto vel = openvdb::Vec3fGrid::create(openvdb::Vec3f(0.0f));
  mass->setName("mass");
  vel->setName("velocity");
  const auto xform = openvdb::math::Transform::createLinearTransform(dx);
  mass->setTransform(xform);
  vel->setTransform(xform->copy());
  vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
  auto macc = mass->getAccessor();
  auto vacc = vel->getAccessor();
  for (size_t b = 0; b < grid.block_count(); ++b) {
    for (int lx = 0; lx < kBlockDim; ++lx)
      for (int ly = 0; ly < kBlockDim; ++ly)
        for (int lz = 0; lz < grid.block_dz; ++lz) {
          const size_t i = b * size_t(grid.block_nodes) + size_t(grid.Local(lx, ly, lz));
          if (grid.mass[i] <= 0) continue;
          const Vec3i n = grid.block_origin[b] + Vec3i(lx, ly, lz);
          const openvdb::Coord c(n.x(), n.y(), n.z());
          macc.setValue(c, static_cast<float>(grid.mass[i]));
          const Vec3& v = grid.velocity_new[i];
          vacc.setValue(c, openvdb::Vec3f(float(v.x()), float(v.y()), float(v.z())));
        }
  }
  try {
    openvdb::io::File file(path);
    openvdb::GridPtrVec grids{mass, vel};
    file.write(grids);
    file.close();
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot write grid file '" + path + "': " + e.what());
  }
}

const char* OpenVdbVersion() { return openvdb::getLibraryVersionString(); }

}  // namespace surge

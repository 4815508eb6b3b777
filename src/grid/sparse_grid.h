// Sparse background grid (DESIGN §5): the set of active blocks is an OpenVDB tree whose 8^3
// leaves are the blocks (vdb_bridge.cpp); node data lives in our own per-block arrays indexed
// [block * kBlockNodes + local]. Hot loops use the block and neighbour tables built here each
// step, never an OpenVDB accessor per particle.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"

namespace surge {

inline constexpr int kBlockBits = 3;
inline constexpr int kBlockDim = 1 << kBlockBits;  // nodes per block edge (x, y; z in 3-D)
inline constexpr int kBlockNodes3 = kBlockDim * kBlockDim * kBlockDim;  // nodes of a 3-D block

class BlockTopology;  // OpenVDB Int32Tree behind a pimpl (vdb_bridge.cpp)

// A block is needed by a particle whose stencil starts in it; `upper` bit d (0..2) says the
// stencil also crosses into the +d neighbour (and all subsets of the set bits are touched).
struct BlockRequest {
  Vec3i block;          // block coordinate = node index >> kBlockBits
  uint8_t upper = 0;    // crossing mask
};

struct SparseGrid {
  SparseGrid();
  ~SparseGrid();
  SparseGrid(SparseGrid&&) noexcept;
  SparseGrid& operator=(SparseGrid&&) noexcept;

  // --- Topology, rebuilt every step by RebuildGrid. ---
  std::vector<Vec3i> block_origin;                 // node index of local node (0,0,0)
  std::vector<std::array<int32_t, 8>> neighbor;    // [b][ox + 2 oy + 4 oz]: block at origin + 8 o, or -1
  std::array<std::vector<int32_t>, 8> colour;      // blocks by parity of their block coordinate
  // --- Particle binning (indices into Particles), stable in particle index. ---
  std::vector<int32_t> particle_block;  // owner block of each particle
  std::vector<uint32_t> block_begin;    // size blocks+1: particles of block b are
  std::vector<uint32_t> sorted;         //   sorted[block_begin[b] .. block_begin[b+1])
  // The work items of the per-particle gathers (G2P, the velocity gradient, the anti-locking
  // gathers): runs sorted[begin .. end) of one block's particles. Blocks without particles are
  // left out (they gathered a halo for nothing), and a block with more than 1/16 of the particles
  // (and more than 256) is cut into several runs, so that a small scene with a few crowded blocks
  // keeps up to 4 threads busy. The cut does not depend on the thread count: each gather writes
  // only its own particles, and the fused stress update's power, summed per run, is then the same
  // for any thread count. Set by BinParticles.
  struct ParticleRun {
    uint32_t block, begin, end;
  };
  std::vector<ParticleRun> runs;
  // --- Node layout: a block's nodes are [b * block_nodes + Local(lx, ly, lz)], lz fastest. A 3-D
  // block holds 8^3 nodes; a 2-D block only its z = 0 plane, 8^2 nodes (block_dz = 1), so a 2-D
  // grid stores and sweeps 8 times fewer nodes (performance issue: bytes per particle). The
  // OpenVDB topology is 8^3 leaves either way. SetDimension (RebuildGrid) chooses. ---
  int block_dz = kBlockDim;        // node planes per block along z: 8 (3-D) or 1 (2-D)
  int block_nodes = kBlockNodes3;  // kBlockDim^2 * block_dz
  void SetDimension(int dim) {
    block_dz = dim == 3 ? kBlockDim : 1;
    block_nodes = kBlockDim * kBlockDim * block_dz;
  }
  int Local(int lx, int ly, int lz) const { return (lx * kBlockDim + ly) * block_dz + lz; }
  Vec3i LocalCoord(int l) const {
    return Vec3i(l / (kBlockDim * block_dz), (l / block_dz) % kBlockDim, l % block_dz);
  }
  // Node coordinate of node index i.
  Vec3i NodeCoord(size_t i) const {
    return block_origin[i / size_t(block_nodes)] + LocalCoord(int(i % size_t(block_nodes)));
  }
  // --- Node fields, size blocks * block_nodes. ---
  std::vector<Real> mass;           // lumped mass m_i [kg]                (2.12)
  // p_i and v_{i,n} share one buffer (performance issue: bytes per particle): ParticleToGrid sums
  // p_i into `momentum`; UpdateGridVelocity overwrites it in place with v_{i,n} and swaps it into
  // `velocity`, leaving `momentum` with velocity's old buffer (empty in USL; MUSL's RemapMomentum
  // sizes it again); BuildTopology swaps it back when `momentum` is empty. Read `momentum` only
  // between P2G and the grid update (and after MUSL's re-map), `velocity` only after the update.
  std::vector<Vec3> momentum;       // p_i [kg m/s]                        (2.12)
  std::vector<Vec3> force;          // f_int + f_ext (without gravity) [N] (2.11)
  std::vector<Vec3> velocity;       // v_{i,n} = p_i / m_i [m/s]           (2.13)
  std::vector<Vec3> velocity_new;   // v_{i,n+1} after boundary conditions (2.14)
  std::vector<Vec3> reaction;       // force on the structures (walls, obstacles) at the node,
                                    // m (v_u - v_c) / dt, this step [N]   (spec §5.3);
                                    // held (sized) only when keep_reaction
  // Whether `reaction` is held: only the force sensors read it (RebuildGrid sets it from the
  // Model); without sensors it stays empty and costs no memory.
  bool keep_reaction = true;
  // --- Per-body velocity fields (Model::field_count > 0 only; else empty), [f * nodes + i]. ---
  int field_count = 0;
  std::vector<Real> field_mass;          // m_i,f [kg]                      (2.12) per field
  std::vector<Vec3> field_momentum;      // p_i,f [kg m/s]
  std::vector<Vec3> field_force;         // f_i,f [N]
  std::vector<Vec3> field_mass_moment;   // sum_p m_p N_ip (x_p - x_i) [kg m]: m_i,f times the offset
                                         // of the field's local centre of mass from the node
  std::vector<Vec3> field_velocity;      // v_i,f at t_n [m/s] (FLIP)
  std::vector<Vec3> field_velocity_new;  // v_i,f at t_{n+1} after contact and walls [m/s]

  // --- Scratch reused by RebuildGrid (no allocation per step after warm-up). ---
  std::vector<std::vector<BlockRequest>> chunk_requests;
  std::vector<BlockRequest> requests;
  std::vector<Vec3i> request_blocks;   // requests' block coordinates, for LookupBlocks
  std::vector<int32_t> request_block;  // block index of each request
  std::vector<uint32_t> chunk_cursor;
  using WallPartial = std::array<Real, 45>;  // 6 faces x 7 sums + 3 (grid_update.cpp)
  std::vector<WallPartial> wall_partials;    // per-block wall reactions (grid_update.cpp)
  struct GhostNode {      // a node with mass beyond a domain wall (MirrorGhostNodes)
    uint32_t node;        // its index
    int32_t wall;         // index into the active walls (ActiveWalls)
    Vec3i mirror;         // node coordinate of its mirror image inside the domain
  };
  std::vector<GhostNode> ghosts;
  // Wall contact (RebuildGrid, WallTouchMarker): per active wall (ActiveWalls order), a bitmap
  // over the node columns normal to it, 1 where a particle touches the wall there this step.
  // Empty `touched` (the gap test off): every wall acts on every node with mass on or beyond it.
  struct WallTouch {
    int axis = 0;          // the wall's normal axis
    Vec3i lo = Vec3i::Zero();  // lowest node index of the map along the two tangential axes
    int n1 = 0, n2 = 0;    // its size along axis (axis + 1) % 3 and (axis + 2) % 3
    std::vector<uint8_t> touched;  // [i1 * n2 + i2]
  };
  std::array<WallTouch, 6> wall_touch;
  std::vector<Vec3i> ghost_mirror_block;   // [2 g]: block of the mirror node, [2 g + 1]: of the
  std::vector<int32_t> ghost_mirror_index; //   node on the wall plane below the ghost (if any)

  std::unique_ptr<BlockTopology> topology;

  size_t block_count() const { return block_origin.size(); }
  size_t ActiveNodeCount() const;  // nodes with mass > 0
};

// Index of grid node `node` (node coordinates), which a particle binned in block `owner` reaches:
// it lies in that block or one of its upper neighbours. -1 when it lies elsewhere or in a block
// that is not active; *block receives its block.
inline int64_t NodeFromOwner(const SparseGrid& grid, size_t owner, const Vec3i& node,
                             int32_t* block) {
  const Vec3i local = node - grid.block_origin[owner];
  int k = 0;
  for (int d = 0; d < 3; ++d) {
    if (local[d] < 0 || local[d] >= 2 * kBlockDim) return -1;
    if (local[d] >= kBlockDim) k |= 1 << d;
  }
  const int32_t blk = grid.neighbor[owner][k];
  if (blk < 0) return -1;
  *block = blk;
  const Vec3i l = local - Vec3i((k & 1) ? kBlockDim : 0, (k & 2) ? kBlockDim : 0,
                                (k & 4) ? kBlockDim : 0);
  return int64_t(blk) * grid.block_nodes + grid.Local(l.x(), l.y(), l.z());
}

// Builds the topology for the given block requests (serial, deterministic: blocks are numbered
// in tree order), the neighbour table and the colour lists, and sizes the node arrays (zeroed).
// The tables depend on the set of blocks only: when it is that of the last call on this grid,
// they are kept as they are.
void BuildTopology(const std::vector<BlockRequest>& requests, SparseGrid& grid);

// For each of n block coordinates, the block index (or -1 when the block is not active).
void LookupBlocks(const SparseGrid& grid, const Vec3i* blocks, size_t n, int32_t* out);

// Writes the grid's mass and velocity as a .vdb file (FloatGrid "mass", Vec3fGrid "velocity",
// voxel size dx). Throws std::runtime_error naming the path on failure.
void ExportGridVdb(const SparseGrid& grid, Real dx, const std::string& path);

// OpenVDB library version string (for `surge info`).
const char* OpenVdbVersion();

}  // namespace surge

// Memory a run needs, estimated before it starts (issue 9, item 5: a scene that needs more than
// the machine has is refused before any particle is allocated, with the estimate; `surge check`
// prints it). Sizes come from the actual element types of Particles, Workspace, SparseGrid and
// the results writer's scratch (sizeof), so they follow the code.
#pragma once
#include <string>

#include "core/math.h"
#include "core/particles.h"

namespace surge {

struct MemoryEstimate {
  double particles = 0;        // particle count
  double grid_blocks = 0;      // active blocks of 8^3 nodes (8^2 in 2-D)
  double particle_bytes = 0;   // Particles SoA + per-particle scratch (workspace, grid binning, writer)
  double grid_bytes = 0;       // node fields of the blocks (with the per-body fields of body_contact)
  double total() const { return particle_bytes + grid_bytes; }
};

// Bytes held per particle during a run (Particles, Workspace and SparseGrid per-particle arrays,
// the snapshot scratch of the results writer), for the optional arrays of `layout` and the step
// scratch of `scratch`.
double BytesPerParticle(const ParticleLayout& layout, const StepScratch& scratch = {});
// Bytes of node fields per active block with `fields` per-body velocity fields (0 without
// body_contact) and the optional node arrays of `scratch`: 8^3 nodes in 3-D, 8^2 in 2-D.
double BytesPerBlock(int fields, int dim, const StepScratch& scratch = {});

// Pre: particles, grid_blocks >= 0.
MemoryEstimate EstimateMemory(double particles, double grid_blocks, int fields, int dim,
                              const ParticleLayout& layout, const StepScratch& scratch = {});

// Blocks of 8^3 nodes covering the box [lo, hi] [m] at cell size dx [m], one block more on each
// side for the stencils that cross a block face; z is one block in 2-D. Pre: dx > 0.
double BlocksCovering(const Vec3& lo, const Vec3& hi, Real dx, int dim);

// Memory this process may still allocate [bytes]: MemAvailable of /proc/meminfo, capped by the
// cgroup v2 limit (memory.max - memory.current) where there is one and by the environment
// variable SURGE_MEMORY_LIMIT [bytes] when set (a budget for shared machines; tests); infinity
// when unknown.
double AvailableMemory();

// "1.23 GB", "456.7 MB".
std::string FormatBytes(double bytes);

}  // namespace surge

// Particle seeding on a lattice aligned with the grid (docs/scene-reference.md "Seeding").
// Internal to surge_scene.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "mesh/mesh.h"
#include "scene/scene_spec.h"

namespace surge {

// Axis-aligned bounds of a region [m] (conservative). `mesh` is the transformed mesh of a
// MeshRegion, nullptr otherwise.
Aabb RegionBounds(const RegionShape& region, const TriangleMesh* mesh);

// Is `x` inside the region? In 2-D (dim == 2) only x and y are tested.
bool InsideRegion(const RegionShape& region, int dim, const TriangleMesh* mesh, const Vec3& x);

// Upper bound on the lattice points x = (i + 1/2) s that SampleRegion scans in `bounds`, as a
// double so that absurd requests can be refused before any allocation; infinity when the
// coordinates are too large for the lattice index range.
double CountLatticePoints(const Aabb& bounds, int dim, Real spacing);

// Lattice points x = (i + 1/2) s (z = 0 in 2-D) inside the region, x fastest, then y, then z.
std::vector<Vec3> SampleRegion(const RegionShape& region, int dim, Real spacing,
                               const TriangleMesh* mesh);

// Adds u s jitter to each seeded coordinate, u uniform in [-1/2, 1/2) from
// std::mt19937_64(seed) as (r >> 11) * 2^-53, drawn particle by particle, axis by axis.
void JitterPositions(int dim, Real spacing, Real jitter, uint64_t seed, std::vector<Vec3>& x);

}  // namespace surge

// Particle seeding: lattice points aligned with the grid (spacing s = dx / particles_per_cell,
// x = (i + 1/2) s), kept if inside the body's region, optionally jittered.
#include "scene/particle_sampling.h"

#include <cmath>
#include <random>

namespace surge {
namespace {

// Even-odd rule point-in-polygon (crossing test of a ray along +x).
bool InsidePolygon(const std::vector<std::array<Real, 2>>& p, Real x, Real y) {
  bool inside = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    const bool straddles = (p[i][1] > y) != (p[j][1] > y);
    if (straddles &&
        x < (p[j][0] - p[i][0]) * (y - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0]) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace

Aabb RegionBounds(const RegionShape& region, const TriangleMesh* mesh) {
  if (const auto* box = std::get_if<BoxRegion>(&region)) return {box->min, box->max};
  if (const auto* sphere = std::get_if<SphereRegion>(&region)) {
    const Vec3 r = Vec3::Constant(sphere->radius);
    return {sphere->center - r, sphere->center + r};
  }
  if (const auto* cyl = std::get_if<CylinderRegion>(&region)) {
    const Vec3 r = Vec3::Constant(cyl->radius);
    return {cyl->base.cwiseMin(cyl->top) - r, cyl->base.cwiseMax(cyl->top) + r};
  }
  if (const auto* poly = std::get_if<PolygonRegion>(&region)) {
    Aabb b{Vec3(poly->points[0][0], poly->points[0][1], poly->z0),
           Vec3(poly->points[0][0], poly->points[0][1], poly->z1)};
    for (const auto& q : poly->points) {
      b.min = b.min.cwiseMin(Vec3(q[0], q[1], poly->z0));
      b.max = b.max.cwiseMax(Vec3(q[0], q[1], poly->z1));
    }
    return b;
  }
  return BoundingBox(*mesh);
}

bool InsideRegion(const RegionShape& region, int dim, const TriangleMesh* mesh, const Vec3& x) {
  if (const auto* box = std::get_if<BoxRegion>(&region)) {
    for (int a = 0; a < dim; ++a) {
      if (!(box->min[a] <= x[a] && x[a] < box->max[a])) return false;
    }
    return true;
  }
  if (const auto* sphere = std::get_if<SphereRegion>(&region)) {
    return (x - sphere->center).head(dim).squaredNorm() < sphere->radius * sphere->radius;
  }
  if (const auto* cyl = std::get_if<CylinderRegion>(&region)) {
    const Vec3 axis = cyl->top - cyl->base;
    const Real length = axis.norm();
    const Vec3 n = axis / length;
    const Vec3 d = x - cyl->base;
    const Real t = d.dot(n);
    return t >= 0 && t < length && (d - t * n).squaredNorm() < cyl->radius * cyl->radius;
  }
  if (const auto* poly = std::get_if<PolygonRegion>(&region)) {
    if (dim == 3 && !(poly->z0 <= x.z() && x.z() < poly->z1)) return false;
    return InsidePolygon(poly->points, x.x(), x.y());
  }
  return InsideMesh(*mesh, x);
}

namespace {
// Index range [lo, hi] of lattice points (i + 1/2) s within [a, b]; one extra index each side
// guards against rounding, the inside test decides.
void LatticeRange(Real a, Real b, Real s, int64_t& lo, int64_t& hi) {
  lo = static_cast<int64_t>(std::floor(a / s - 0.5)) - 1;
  hi = static_cast<int64_t>(std::ceil(b / s - 0.5)) + 1;
}
}  // namespace

double CountLatticePoints(const Aabb& bounds, int dim, Real spacing) {
  // In doubles, without the integer casts of LatticeRange: coordinates far beyond the int64
  // lattice range (or non-finite) give infinity, which the caller refuses.
  double count = 1;
  for (int a = 0; a < dim; ++a) {
    const double lo = bounds.min[a] / spacing, hi = bounds.max[a] / spacing;
    if (!(std::abs(lo) < 1e15 && std::abs(hi) < 1e15)) return HUGE_VAL;
    count *= std::floor(hi - lo) + 5;  // points in [lo, hi] plus the guard indices
  }
  return count;
}

std::vector<Vec3> SampleRegion(const RegionShape& region, int dim, Real spacing,
                               const TriangleMesh* mesh) {
  const Aabb b = RegionBounds(region, mesh);
  int64_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  for (int a = 0; a < dim; ++a) LatticeRange(b.min[a], b.max[a], spacing, lo[a], hi[a]);
  std::vector<Vec3> x;
  for (int64_t k = lo[2]; k <= hi[2]; ++k) {
    for (int64_t j = lo[1]; j <= hi[1]; ++j) {
      for (int64_t i = lo[0]; i <= hi[0]; ++i) {
        const Vec3 p((i + 0.5) * spacing, (j + 0.5) * spacing, dim == 3 ? (k + 0.5) * spacing : 0.0);
        if (InsideRegion(region, dim, mesh, p)) x.push_back(p);
      }
    }
  }
  return x;
}

void JitterPositions(int dim, Real spacing, Real jitter, uint64_t seed, std::vector<Vec3>& x) {
  if (jitter <= 0) return;
  std::mt19937_64 rng(seed);
  for (Vec3& p : x) {
    for (int a = 0; a < dim; ++a) {
      const Real u = static_cast<Real>(rng() >> 11) * 0x1.0p-53 - 0.5;  // [-1/2, 1/2)
      p[a] += u * spacing * jitter;
    }
  }
}

}  // namespace surge

// Memory estimate of a run (memory_estimate.h).
#include "scene/memory_estimate.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "core/particles.h"
#include "grid/sparse_grid.h"
#include "step/workspace.h"

namespace surge {
namespace {

// Bytes of one element of a std::vector member type.
template <typename V>
constexpr double Elem() {
  return double(sizeof(typename V::value_type));
}

// A number from the first line of a file, or -1.
double ReadNumber(const char* path) {
  std::ifstream in(path);
  std::string word;
  if (!(in >> word) || word == "max") return -1;
  try {
    return std::stod(word);
  } catch (...) {
    return -1;
  }
}

}  // namespace

double BytesPerParticle(const ParticleLayout& layout, const StepScratch& scratch) {
  using P = Particles;
  // State: every Particles array the layout holds.
  double b = Elem<decltype(P::x)>() + Elem<decltype(P::v)>() + Elem<decltype(P::F)>() +
             Elem<decltype(P::stress)>() + Elem<decltype(P::mass)>() +
             Elem<decltype(P::volume0)>() + Elem<decltype(P::material)>() +
             Elem<decltype(P::body)>() + Elem<decltype(P::id)>();
  if (layout.affine) b += Elem<decltype(P::C)>();
  if (layout.strain) b += Elem<decltype(P::strain)>();
  if (layout.elastic_b) b += Elem<decltype(P::elastic_b)>();
  if (layout.history) b += double(layout.history_slots) * sizeof(Real);
  if (layout.ext_force) b += Elem<decltype(P::ext_force)>();
  // Workspace per-particle scratch.
  using W = Workspace;
  b += Elem<decltype(W::exit_flag)>() + Elem<decltype(W::reorder)>();
  if (scratch.velocity_gradient) b += Elem<decltype(W::velocity_gradient)>();
  if (scratch.x_n) b += Elem<decltype(W::x_new)>();
  using A = AntiLockingScratch;
  if (scratch.theta) b += Elem<decltype(A::theta)>();
  if (scratch.tensor) b += Elem<decltype(A::tensor)>() + Elem<decltype(A::tensor_ok)>();
  if (scratch.inv_stretch) b += Elem<decltype(A::inv_stretch)>();
  if (scratch.theta_bar) b += Elem<decltype(A::theta_bar)>();
  if (scratch.shift) b += Elem<decltype(ShiftingScratch::shift)>();
  // Grid binning.
  using G = SparseGrid;
  b += Elem<decltype(G::particle_block)>() + Elem<decltype(G::sorted)>();
  // Results writer snapshot scratch (hdf5_writer.cpp): one derived field at a time, at most the
  // stress (6 float64).
  b += 6 * sizeof(double);
  return b;
}

double BytesPerBlock(int fields, int dim, const StepScratch& scratch) {
  using G = SparseGrid;
  // momentum and velocity share one buffer (SparseGrid::momentum) but in MUSL.
  double node = Elem<decltype(G::mass)>() + Elem<decltype(G::momentum)>() +
                Elem<decltype(G::force)>() + Elem<decltype(G::velocity_new)>();
  if (scratch.node_momentum) node += Elem<decltype(G::velocity)>();
  if (scratch.node_reaction) node += Elem<decltype(G::reaction)>();
  const double field = Elem<decltype(G::field_mass)>() + Elem<decltype(G::field_momentum)>() +
                       Elem<decltype(G::field_force)>() + Elem<decltype(G::field_mass_moment)>() +
                       Elem<decltype(G::field_velocity)>() + Elem<decltype(G::field_velocity_new)>();
  const double topology = Elem<decltype(G::block_origin)>() + Elem<decltype(G::neighbor)>() +
                          Elem<decltype(G::wall_partials)>();
  const double nodes = kBlockDim * kBlockDim * (dim == 3 ? kBlockDim : 1);  // SparseGrid::SetDimension
  return nodes * (node + fields * field) + topology;
}

MemoryEstimate EstimateMemory(double particles, double grid_blocks, int fields, int dim,
                              const ParticleLayout& layout, const StepScratch& scratch) {
  MemoryEstimate m;
  m.particles = particles;
  m.grid_blocks = grid_blocks;
  m.particle_bytes = particles * BytesPerParticle(layout, scratch);
  m.grid_bytes = grid_blocks * BytesPerBlock(fields, dim, scratch);
  return m;
}

double BlocksCovering(const Vec3& lo, const Vec3& hi, Real dx, int dim) {
  const double block = double(kBlockDim) * dx;  // [m]
  double blocks = 1;
  for (int a = 0; a < (dim == 2 ? 2 : 3); ++a) {
    const double extent = std::max(0.0, double(hi[a] - lo[a]));
    blocks *= std::ceil(extent / block) + 2;
  }
  return blocks;
}

double AvailableMemory() {
  double available = std::numeric_limits<double>::infinity();
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream in(line.substr(13));
    double kb = 0;
    if (in >> kb) available = kb * 1024.0;
  }
  if (!std::isfinite(available)) {  // no /proc/meminfo: free physical pages
    const long pages = sysconf(_SC_AVPHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    if (pages > 0 && size > 0) available = double(pages) * double(size);
  }
  const double limit = ReadNumber("/sys/fs/cgroup/memory.max");
  const double used = ReadNumber("/sys/fs/cgroup/memory.current");
  if (limit > 0 && used >= 0) available = std::min(available, std::max(0.0, limit - used));
  if (const char* budget = std::getenv("SURGE_MEMORY_LIMIT")) {
    char* end = nullptr;
    const double v = std::strtod(budget, &end);
    if (end != budget && v > 0) available = std::min(available, v);
  }
  return available;
}

std::string FormatBytes(double bytes) {
  char buf[48];
  if (bytes >= 1e9)
    std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  else
    std::snprintf(buf, sizeof buf, "%.1f MB", bytes / 1e6);
  return buf;
}

}  // namespace surge

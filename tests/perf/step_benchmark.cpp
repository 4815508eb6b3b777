// Step throughput in particle-updates per second (Google Benchmark). A 3-D block (Neo-Hookean, or
// one of the soil models) of
// about 100 000 particles (23^3 cells x 8 particles per cell, dx = 0.04 m), thrown at 2 m/s
// through an open domain with gravity so that blocks appear and disappear. Arguments: shape
// function, transfer, threads. Run: build/tests/perf/step_benchmark (see docs/benchmarks.md).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <thread>

#include "core/simd.h"
#include "scene/scene.h"
#include "step/step.h"

// Every operator new of the process is counted (calls and bytes), so that TimeSteps can report
// the heap allocations a step makes after warm-up (issue #7: none expected).
namespace {
std::atomic<int64_t> g_new_calls{0}, g_new_bytes{0};

void* CountedNew(std::size_t size, std::size_t align) {
  g_new_calls.fetch_add(1, std::memory_order_relaxed);
  g_new_bytes.fetch_add(int64_t(size), std::memory_order_relaxed);
  void* p = align > alignof(std::max_align_t)
                ? std::aligned_alloc(align, (size + align - 1) / align * align)
                : std::malloc(size ? size : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t size) { return CountedNew(size, 0); }
void* operator new[](std::size_t size) { return CountedNew(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return CountedNew(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) {
  return CountedNew(size, std::size_t(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace surge {
namespace {

// Materials of the block: the elastic default and the soil models (seed column-collapse sand).
constexpr const char* kRubber =
    "{model: neo_hookean, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}";
constexpr const char* kModifiedDp =
    "{model: modified_drucker_prager, density: 2200, bulk_modulus: 29.5e6, shear_modulus: 13.6e6, "
    "a0: 35, a3: 0.2, a4: 10, dilation: zero}";
constexpr const char* kMatsuokaNakaiDp =
    "{model: matsuoka_nakai_dp, density: 2200, bulk_modulus: 29.5e6, shear_modulus: 13.6e6, "
    "a0: 35, a3: 0.2, a4: 10, dilation: zero}";
constexpr const char* kSmoothCap =
    "{model: drucker_prager_smooth_cap, density: 1950.55, bulk_modulus: 8.33e6, "
    "shear_modulus: 3.85e6, friction_angle_deg: 20, yield_stress: 10, associativity: 0.05}";

// Obstacles in the block's path (it flies towards +x at 2 m/s and starts 0.017 m from them): a
// box wall, and the project's mound mesh scaled to 1.8 m x 0.9 m, lying on its side with its
// top 0.067 m ahead of the block (FCL distance queries).
constexpr const char* kNoObstacles = "";
constexpr const char* kBoxObstacle = R"(obstacles:
  - name: wall
    shape: {box: {min: [0.95, -2, -2], max: [1.5, 3, 3]}}
    contact: {friction: 0.3}
)";
// Configured but never reached: a box 5 m below the block's path (shows that the obstacle stages
// cost next to nothing when no block is near an obstacle).
constexpr const char* kFarObstacle = R"(obstacles:
  - name: far_wall
    shape: {box: {min: [-1, -8, -1], max: [3, -7, 3]}}
    contact: {friction: 0.3}
)";
const std::string kMeshObstacle = std::string(R"(obstacles:
  - name: mound
    shape: {mesh: {file: )") + SURGE_SOURCE_DIR + R"(/assets/mound.obj, scale: 0.3, rotate_deg: [0, 0, 90], translate: [1.9, 0.45, 0.45]}}
    contact: {friction: 0.3}
)";

std::string BlockScene(const char* shape, const char* transfer, const char* material,
                       const std::string& obstacles = kNoObstacles) {
  return std::string(R"(name: bench_block
dimension: 3
time: {end: 100.0, cfl: 0.4}
gravity: [0, -9.81, 0]
grid: {cell_size: 0.04, shape_function: )") +
         shape + ", transfer: " + transfer + R"(}
domain: {min: [-10, -10, -10], max: [10, 10, 10]}
materials:
  rubber: )" + std::string(material) + R"(
bodies:
  - name: block
    material: rubber
    region: {box: {min: [0.013, 0.021, 0.007], max: [0.933, 0.941, 0.927]}}
    particles_per_cell: 2
    velocity: [2.0, 1.0, 0.5]
output: {every: 0, energy: false}
)" + obstacles;
}

// Takes `warmup` untimed steps, then times whole Step() calls; counters: particles,
// particle-updates per second, milliseconds per stage and heap allocations per step.
void TimeSteps(benchmark::State& bm, LoadedScene& scene, Workspace& work, int warmup) {
  const Pipeline pipeline = MakePipeline(scene.model);
  StepReport report;
  for (int i = 0; i < warmup; ++i) Step(scene.model, pipeline, scene.state, work, report);
  report.stage_seconds.fill(0);
  const size_t n = scene.state.particles.size();
  int64_t steps = 0;
  const int64_t calls0 = g_new_calls.load(), bytes0 = g_new_bytes.load();
  for (auto _ : bm) {
    Step(scene.model, pipeline, scene.state, work, report);
    ++steps;
  }
  // Heap allocations per timed step (operator new, every thread), after the warm-up steps.
  bm.counters["allocs_per_step"] = double(g_new_calls.load() - calls0) / double(steps);
  bm.counters["alloc_bytes_per_step"] = double(g_new_bytes.load() - bytes0) / double(steps);
  bm.counters["particles"] = double(n);
  bm.counters["wide_simd"] = WideSimd() ? 1 : 0;
  bm.counters["updates_per_s"] =
      benchmark::Counter(double(n) * double(steps), benchmark::Counter::kIsRate);
  for (int s = 0; s < kStageCount; ++s)
    if (report.stage_seconds[s] > 0)
      bm.counters[std::string("ms_") + StageName(Stage(s))] =
          1e3 * report.stage_seconds[s] / double(steps);
}

void BM_Step(benchmark::State& bm, const char* shape, const char* transfer,
             const char* material = kRubber, const std::string& obstacles = kNoObstacles) {
  const int threads = int(bm.range(0));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  LoadedScene scene = LoadSceneFromString(BlockScene(shape, transfer, material, obstacles),
                                          "bench_block.yaml");
  Workspace work;
  TimeSteps(bm, scene, work, 3);
}

BENCHMARK_CAPTURE(BM_Step, quadratic_apic, "quadratic_bspline", "apic")
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, cubic_apic, "cubic_bspline", "apic")
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, linear_flip, "linear", "flip")
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
// Soil models on the same block (it flies and spins; under gravity and impact-free flight the
// stress stays near zero, so the returns exercised are mostly apex/cutoff and elastic: this
// measures the per-particle cost of the trial state, the eigen-solve and the dispatch).
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_modified_dp, "quadratic_bspline", "apic", kModifiedDp)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_smooth_cap, "quadratic_bspline", "apic", kSmoothCap)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_mn_dp, "quadratic_bspline", "apic", kMatsuokaNakaiDp)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
// Rigid obstacles in the block's path: the cost of the node contact and the particle projection
// (stages obstacle_contact, obstacle_projection) on top of the plain block.
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_box_obstacle, "quadratic_bspline", "apic", kRubber,
                  kBoxObstacle)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_far_obstacle, "quadratic_bspline", "apic", kRubber,
                  kFarObstacle)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_mesh_obstacle, "quadratic_bspline", "apic", kRubber,
                  kMeshObstacle)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

// --- Column collapse at a given particle count (performance issue): a column 1 x 2 x 1 (3-D) or
// 1 x 2 (2-D) in cells, 2 particles per cell per axis, dx = 0.02 m, standing in the corner of
// slip symmetry walls on a frictional floor (the soil with a K0 = 0.5 geostatic start), released at
// t = 0 (seed §7.2 set-up). Arguments: particle count, threads. Counters add the exact bytes per
// particle of State + Workspace (vector capacities, grid included) and the process RSS per particle.

constexpr const char* kWater =
    "{model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e6, viscosity: 1.0e-3}";
// The same water with the linear node fit of the trace (the settle recipe's anti-locking,
// docs/antilocking.md "Linear node fit").
constexpr const char* kWaterLinearFit =
    "{model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e6, viscosity: 1.0e-3, "
    "antilocking: {method: node, fit: linear}}";

std::string ColumnScene(int dim, double particles, const char* material, bool geostatic) {
  const double dx = 0.02, ppc = dim == 3 ? 8 : 4;
  // cells = n * 2n (* n): n = (N / (2 ppc))^(1/dim)
  const double n = std::round(std::pow(particles / (2 * ppc), 1.0 / dim));
  const double w = n * dx, h = 2 * n * dx;
  auto num = [](double v) { return std::to_string(v); };
  const std::string zmin = dim == 3 ? ", 0]" : "]", zmax = dim == 3 ? ", " + num(w) + "]" : "]";
  const std::string dmax = dim == 3 ? ", " + num(3 * w) + "]" : "]";
  return std::string("name: bench_column\ndimension: ") + std::to_string(dim) + R"(
time: {end: 100.0, cfl: 0.4}
gravity: )" + (dim == 3 ? "[0, -9.81, 0]" : "[0, -9.81]") + R"(
grid: {cell_size: )" + num(dx) + R"(, shape_function: quadratic_bspline, transfer: apic}
domain:
  min: )" + (dim == 3 ? "[0, 0, 0]" : "[0, 0]") + R"(
  max: [)" + num(3 * w) + ", " + num(1.2 * h + 4 * dx) + dmax + R"(
  walls: )" + (dim == 3 ? "{x-: slip, z-: slip, y-: {friction: 0.5}, x+: slip, z+: slip}"
                       : "{x-: slip, y-: {friction: 0.5}, x+: slip}") + R"(
materials:
  soil: )" + std::string(material) + R"(
bodies:
  - name: column
    material: soil
    region: {box: {min: )" + (dim == 3 ? "[0, 0, 0]" : "[0, 0]") + ", max: [" + num(w) + ", " +
         num(h) + zmax + R"(}}
    particles_per_cell: 2
)" + (geostatic ? "    initial_stress: {geostatic: {k0: 0.5}}\n" : "") +
         "output: {every: 0, energy: false}\n";
}

size_t ResidentBytes() {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return size_t(resident) * size_t(sysconf(_SC_PAGESIZE));
}

template <class T>
size_t Bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

size_t Bytes(const HistoryArray& h) { return h.capacity() * sizeof(Real); }

// Bytes held by the particle arrays and the step's scratch (grid included).
size_t StateBytes(const State& state, const Workspace& w) {
  const Particles& P = state.particles;
  size_t b = Bytes(P.x) + Bytes(P.v) + Bytes(P.C) + Bytes(P.F) + Bytes(P.stress) +
             Bytes(P.strain) + Bytes(P.elastic_b) + Bytes(P.history) + Bytes(P.mass) +
             Bytes(P.volume0) + Bytes(P.ext_force) + Bytes(P.material) + Bytes(P.body) +
             Bytes(P.id);
  const SparseGrid& g = w.grid;
  b += Bytes(g.block_origin) + Bytes(g.neighbor) + Bytes(g.particle_block) +
       Bytes(g.block_begin) + Bytes(g.sorted) + Bytes(g.mass) + Bytes(g.momentum) +
       Bytes(g.force) + Bytes(g.velocity) + Bytes(g.velocity_new) + Bytes(g.reaction) +
       Bytes(g.requests) + Bytes(g.chunk_cursor) +
       Bytes(g.wall_partials);
  for (const auto& c : g.colour) b += Bytes(c);
  for (const auto& c : g.chunk_requests) b += Bytes(c);
  b += Bytes(w.velocity_gradient) + Bytes(w.x_new) + Bytes(w.exit_flag) + Bytes(w.reorder);
  const AntiLockingScratch& a = w.antilocking;  // empty without anti-locking
  b += Bytes(a.weight) + Bytes(a.weighted) + Bytes(a.theta) + Bytes(a.tensor) +
       Bytes(a.inv_stretch) + Bytes(a.tensor_ok) + Bytes(a.theta_bar) + Bytes(a.moments) +
       Bytes(a.node_fit) + Bytes(a.node_sum) + Bytes(a.node_count);
  return b;
}

void BM_Column(benchmark::State& bm, int dim, const char* material) {
  const double wanted = double(bm.range(0));
  const int threads = int(bm.range(1));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  LoadedScene scene =
      LoadSceneFromString(ColumnScene(dim, wanted, material, material == kSmoothCap), "bench_column.yaml");
  Workspace work;
  TimeSteps(bm, scene, work, 2);
  const double n = double(scene.state.particles.size());
  bm.counters["bytes_per_particle"] = double(StateBytes(scene.state, work)) / n;
  bm.counters["rss_per_particle"] = double(ResidentBytes()) / n;
}

void ColumnArgs(benchmark::internal::Benchmark* b) {
  for (int64_t n : {10000, 100000, 1000000})
    for (int64_t t : {1, 2}) b->Args({n, t});
  b->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);
}

BENCHMARK_CAPTURE(BM_Column, dp_3d, 3, kSmoothCap)->Apply(ColumnArgs);
BENCHMARK_CAPTURE(BM_Column, dp_3d_4M, 3, kSmoothCap)
    ->Args({4000000, 1})->Args({4000000, 2})->Iterations(3)->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Column, dp_2d, 2, kSmoothCap)->Apply(ColumnArgs);
BENCHMARK_CAPTURE(BM_Column, elastic_3d, 3, kRubber)->Apply(ColumnArgs);
BENCHMARK_CAPTURE(BM_Column, water_3d, 3, kWater)->Apply(ColumnArgs);
BENCHMARK_CAPTURE(BM_Column, water_linear_fit_3d, 3, kWaterLinearFit)
    ->Args({10000, 1})->Args({10000, 2})->Args({100000, 1})->Args({100000, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The machine, not Surge: how long one cache line takes to go from one core to the other and
// back (two threads hand a counter back and forth; counter: ns per round trip). On the 2-vCPU
// EPYC VM this is about 420 ns, which is why the step's loops keep each thread on the particles
// and blocks it owns (src/transfer/owned_loops.h, docs/benchmarks.md sixteenth increment).
void BM_CoreToCoreRoundTrip(benchmark::State& state) {
  if (std::thread::hardware_concurrency() < 2) {
    state.SkipWithError("needs two cores (the threads spin)");
    return;
  }
  alignas(64) std::atomic<int64_t> flag{0};
  constexpr int64_t kTrips = 200000;
  double seconds = 0;
  for (auto _ : state) {
    flag.store(0);
    const auto start = std::chrono::steady_clock::now();
    std::thread other([&] {
      for (int64_t i = 0; i < kTrips; ++i) {
        while (flag.load(std::memory_order_acquire) != 2 * i + 1) {
        }
        flag.store(2 * i + 2, std::memory_order_release);
      }
    });
    for (int64_t i = 0; i < kTrips; ++i) {
      flag.store(2 * i + 1, std::memory_order_release);
      while (flag.load(std::memory_order_acquire) != 2 * i + 2) {
      }
    }
    other.join();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  state.counters["ns_per_round_trip"] = seconds * 1e9 / (double(kTrips) * double(state.iterations()));
}
BENCHMARK(BM_CoreToCoreRoundTrip)->Unit(benchmark::kMillisecond)->UseRealTime();

// SURGE_WIDE_SIMD=0 runs the portable builds of the kernels (core/simd.h) on an AVX machine, so
// one binary measures both; the `wide_simd` counter says which ran.
const bool kWideSimdFromEnv = [] {
  const char* v = std::getenv("SURGE_WIDE_SIMD");
  if (v && std::string(v) == "0") SetWideSimd(false);
  return WideSimd();
}();

}  // namespace
}  // namespace surge

BENCHMARK_MAIN();

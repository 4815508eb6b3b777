// Step throughput in particle-updates per second (Google Benchmark). A 3-D block (Neo-Hookean, or
// one of the soil models) of
// about 100 000 particles (23^3 cells x 8 particles per cell, dx = 0.04 m), thrown at 2 m/s
// through an open domain with gravity so that blocks appear and disappear. Arguments: shape
// function, transfer, threads. Run: build/tests/perf/step_benchmark (see docs/benchmarks.md).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <string>

#include "scene/scene.h"
#include "step/step.h"

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

void BM_Step(benchmark::State& bm, const char* shape, const char* transfer,
             const char* material = kRubber, const std::string& obstacles = kNoObstacles) {
  const int threads = int(bm.range(0));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  LoadedScene scene = LoadSceneFromString(BlockScene(shape, transfer, material, obstacles),
                                          "bench_block.yaml");
  const Pipeline pipeline = MakePipeline(scene.model);
  Workspace work;
  StepReport report;
  for (int i = 0; i < 3; ++i) Step(scene.model, pipeline, scene.state, work, report);  // warm-up
  report.stage_seconds.fill(0);
  const size_t n = scene.state.particles.size();
  int64_t steps = 0;
  for (auto _ : bm) {
    Step(scene.model, pipeline, scene.state, work, report);
    ++steps;
  }
  bm.counters["particles"] = double(n);
  bm.counters["updates_per_s"] = benchmark::Counter(double(n) * double(steps), benchmark::Counter::kIsRate);
  for (int s = 0; s < kStageCount; ++s)
    if (report.stage_seconds[s] > 0)
      bm.counters[std::string("ms_") + StageName(Stage(s))] = 1e3 * report.stage_seconds[s] / double(steps);
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
BENCHMARK_CAPTURE(BM_Step, quadratic_apic_mesh_obstacle, "quadratic_bspline", "apic", kRubber,
                  kMeshObstacle)
    ->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);

}  // namespace
}  // namespace surge

BENCHMARK_MAIN();

// Cost of the spectral decomposition of b^e_tr in the principal-space stress updates (Mast 2013
// Table 3.4, step 2): SymmetricEigen (materials/symmetric_eigen.h) against Eigen's iterative
// SelfAdjointEigenSolver, on 4096 matrices b = f f^T, f = 0.999 I + N(0, sd) (sd = 1e-4, 1e-2, 0.3
// as the argument x 1e-4), and on exactly diagonal ones. Run: build/tests/perf/material_benchmark
// (docs/benchmarks.md).
#include <benchmark/benchmark.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

#include "materials/symmetric_eigen.h"

namespace surge {
namespace {

std::vector<Mat3> Matrices(double sd, bool diagonal) {
  std::mt19937 g(1);
  std::normal_distribution<double> n(0, sd);
  std::vector<Mat3> out(4096);
  for (Mat3& b : out) {
    Mat3 f = 0.999 * Mat3::Identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (!diagonal || i == j) f(i, j) += n(g);
    b = f * f.transpose();
  }
  return out;
}

void BM_SymmetricEigen(benchmark::State& bm, bool diagonal) {
  const std::vector<Mat3> b = Matrices(double(bm.range(0)) * 1e-4, diagonal);
  Vec3 values;
  Mat3 vectors;
  size_t k = 0;
  for (auto _ : bm) {
    SymmetricEigen(b[k++ & 4095], values, vectors);
    benchmark::DoNotOptimize(values);
    benchmark::DoNotOptimize(vectors);
  }
}

// Two matrices per call (SymmetricEigen2); the counter is per decomposition, as above.
void BM_SymmetricEigen2(benchmark::State& bm, bool diagonal) {
  const std::vector<Mat3> b = Matrices(double(bm.range(0)) * 1e-4, diagonal);
  Vec3 values0, values1;
  Mat3 vectors0, vectors1;
  size_t k = 0;
  for (auto _ : bm) {
    SymmetricEigen2(b[k & 4095], b[(k + 1) & 4095], values0, vectors0, values1, vectors1);
    k += 2;
    benchmark::DoNotOptimize(values0);
    benchmark::DoNotOptimize(vectors0);
    benchmark::DoNotOptimize(values1);
    benchmark::DoNotOptimize(vectors1);
  }
  bm.SetItemsProcessed(int64_t(bm.iterations()) * 2);
}

void BM_EigenSelfAdjoint(benchmark::State& bm, bool diagonal) {
  const std::vector<Mat3> b = Matrices(double(bm.range(0)) * 1e-4, diagonal);
  size_t k = 0;
  for (auto _ : bm) {
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(b[k++ & 4095]);
    benchmark::DoNotOptimize(eig.eigenvalues());
    benchmark::DoNotOptimize(eig.eigenvectors());
  }
}

BENCHMARK_CAPTURE(BM_SymmetricEigen, full, false)->Arg(1)->Arg(100)->Arg(3000);
BENCHMARK_CAPTURE(BM_SymmetricEigen2, full, false)->Arg(1)->Arg(100)->Arg(3000);
BENCHMARK_CAPTURE(BM_EigenSelfAdjoint, full, false)->Arg(1)->Arg(100)->Arg(3000);
BENCHMARK_CAPTURE(BM_SymmetricEigen, diagonal, true)->Arg(100);
BENCHMARK_CAPTURE(BM_EigenSelfAdjoint, diagonal, true)->Arg(100);

}  // namespace
}  // namespace surge

BENCHMARK_MAIN();

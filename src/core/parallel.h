// Thin wrappers over oneTBB so that every parallel loop has a thread-count-independent
// decomposition where the result depends on it (deterministic reductions, STYLE H.4 / DESIGN §5).
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cstddef>

namespace surge {

// Runs f(i) for i in [0, n); order unspecified. f must only write data owned by i.
template <typename F>
void ParallelFor(size_t n, size_t grain, const F& f) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, std::max<size_t>(grain, 1)),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) f(i);
                    });
}

// Runs f(i) for i in [0, n) in contiguous parts, thread t always taking [n t / T, n (t + 1) / T)
// (tbb::static_partitioner): for items of about equal cost in particle order, so that each
// thread keeps the particles it owns in the other loops (transfer/owned_loops.h).
template <typename F>
void ParallelForStatic(size_t n, const F& f) {
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, n, 1),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) f(i);
      },
      tbb::static_partitioner());
}

// Threads a parallel loop can use now: the arena's, capped by the run's -t limit (global_control).
// Only work splits that leave results unchanged may depend on it.
inline size_t WorkerThreads() {
  return std::min(size_t(tbb::this_task_arena::max_concurrency()),
                  tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

// Number of fixed chunks used by deterministic reductions: independent of the thread count.
inline constexpr size_t kReductionChunks = 64;

// Splits [0, n) into kReductionChunks contiguous chunks and runs f(chunk, begin, end) in
// parallel. Partial results stored per chunk and combined in chunk order are bitwise
// reproducible for any thread count. tbb::static_partitioner gives thread t the chunks of
// [n t / T, n (t + 1) / T) in every call, the particles it owns in the grid loops too
// (transfer/owned_loops.h).
template <typename F>
void ParallelChunks(size_t n, const F& f) {
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, kReductionChunks, 1),
      [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c)
          f(c, n * c / kReductionChunks, n * (c + 1) / kReductionChunks);
      },
      tbb::static_partitioner());
}

// Atomic minimum and maximum of a double slot (compare-exchange loops). A minimum or maximum is
// the same in any order, so slots filled this way do not depend on the thread count.
inline void AtomicMin(double& slot, double value) {
  std::atomic_ref<double> a(slot);
  double cur = a.load(std::memory_order_relaxed);
  while (value < cur && !a.compare_exchange_weak(cur, value, std::memory_order_relaxed)) {
  }
}
inline void AtomicMax(double& slot, double value) {
  std::atomic_ref<double> a(slot);
  double cur = a.load(std::memory_order_relaxed);
  while (value > cur && !a.compare_exchange_weak(cur, value, std::memory_order_relaxed)) {
  }
}

}  // namespace surge

// Parallel loops on a thread count that the caller passes in (house style:
// parallelism is never global state). Bodies must make the result independent
// of the thread count: each index writes only its own outputs.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cassert>

namespace scanbench::core {

// The largest thread count a caller may ask for (the CLI's --threads takes
// 0 … kMaxThreads). What a machine runs is at most its cores.
inline constexpr int kMaxThreads = 1024;

// The number of workers `threads` stands for: every core when 0, else
// `threads`, but never more than the cores it may use (more would only
// oversubscribe them, and make TBB and Ceres warn). Results never depend on
// it. Asserts 0 <= threads <= kMaxThreads.
inline int worker_count(int threads) {
  assert(threads >= 0 && threads <= kMaxThreads && "a thread count outside 0 … kMaxThreads");
  // The cores this process may run on (its affinity mask and cgroup quota).
  const int cores = std::max(1, tbb::info::default_concurrency());
  return threads > 0 ? std::min(threads, cores) : cores;
}

// A TBB arena of worker_count(threads) workers.
inline tbb::task_arena worker_arena(int threads) {
  return tbb::task_arena(worker_count(threads));
}

// Calls body(k) for k in [0, count) on worker_count(threads) workers,
// handing out `grain` consecutive indices at a time.
template <typename Body>
void parallel_for_index(int count, int threads, Body&& body, int grain = 1) {
  tbb::task_arena arena = worker_arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, count, grain),
                      [&](const tbb::blocked_range<int>& range) {
                        for (int k = range.begin(); k < range.end(); ++k) body(k);
                      });
  });
}

}  // namespace scanbench::core

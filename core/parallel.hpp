// Parallel loops on a thread count that the caller passes in (house style:
// parallelism is never global state). Bodies must make the result independent
// of the thread count: each index writes only its own outputs.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <thread>

namespace scanbench::core {

// The number of workers `threads` stands for: itself when positive, else
// every core (at least 1).
inline int worker_count(int threads) {
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Calls body(k) for k in [0, count) on `threads` workers (0 = all cores),
// handing out `grain` consecutive indices at a time.
template <typename Body>
void parallel_for_index(int count, int threads, Body&& body, int grain = 1) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, count, grain),
                      [&](const tbb::blocked_range<int>& range) {
                        for (int k = range.begin(); k < range.end(); ++k) body(k);
                      });
  });
}

}  // namespace scanbench::core

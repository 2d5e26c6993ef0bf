// Wall-clock seconds for the timings that results report.
#pragma once

#include <chrono>

namespace scanbench::acquisition {

// Seconds [s] elapsed since `start` on the steady clock.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace scanbench::acquisition

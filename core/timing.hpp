// Wall-clock seconds for the timings that results report.
#pragma once

#include <chrono>

namespace scanbench::core {

// Seconds [s] elapsed since `start` on the steady clock.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace scanbench::core

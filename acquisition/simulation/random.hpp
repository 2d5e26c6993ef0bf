// Deterministic random numbers for the simulation. Standard-library
// distributions are implementation-defined, so the same seed could give other
// sites on another toolchain; these are specified here, bit for bit. So is
// the order of the draws: never two draws in the arguments of one call (or
// constructor), or in the operands of one operator, whose order of
// evaluation C++ leaves open (GCC took the last argument and the right
// operand first, clang the first). Where the simulation once did, its draws
// are now spelt out in GCC's order, which made the sites every bench was
// measured on (the same files, byte for byte).
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace scanbench::acquisition::sim {

// SplitMix64 finaliser: a well-mixed 64-bit hash of x.
constexpr std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Hash of several values, e.g. (seed, scan, row, col): lets every pixel draw
// its own noise independently of thread scheduling.
constexpr std::uint64_t hash_combine(std::uint64_t a, std::uint64_t b) { return mix64(a ^ mix64(b)); }

class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return mix64(state_);
  }
  // Uniform in [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Integer in [lo, hi], inclusive.
  int integer(int lo, int hi) {
    return lo + static_cast<int>(uniform() * (static_cast<double>(hi) - lo + 1.0));
  }
  // Standard normal by Box–Muller (one of the pair; simple and exact enough).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  std::uint64_t state_;
};

}  // namespace scanbench::acquisition::sim

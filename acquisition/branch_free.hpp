// Small helpers for loops that GCC's vectorizer should accept with the
// project's portable flags (x86-64 baseline, errno-setting math, trapping
// math): it turns conditional expressions on floats back into branches and
// keeps a scalar branch in std::sqrt for errno, and a branch stops it.
#pragma once

#include <bit>
#include <cstdint>

// Function multiversioning for the stage's widest vector loops: an AVX2
// clone next to the baseline x86-64 one, chosen once at load time, so the
// binary still runs on any x86-64. Only AVX2, not FMA: without fused
// multiply-adds and with no reductions in these loops, both clones give
// identical results.
// A build may define it empty to compare the two.
#ifndef SCANBENCH_VECTOR_CLONES
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SCANBENCH_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SCANBENCH_VECTOR_CLONES
#endif
#endif

namespace scanbench::acquisition {

// All bits set when b, none otherwise.
inline std::uint32_t all_bits(bool b) {
  return b ? ~0u : 0u;
}

// `value` where `keep` is all ones, +0 where it is zero: a select through
// which no non-finite value can leak (unlike value · 0).
inline float select_bits(float value, std::uint32_t keep) {
  return std::bit_cast<float>(std::bit_cast<std::uint32_t>(value) & keep);
}

// The same for doubles (a separate name, so that a 32-bit mask cannot be
// widened into a wrong one by overload resolution).
inline std::uint64_t all_bits64(bool b) {
  return b ? ~std::uint64_t{0} : 0;
}

inline double select_bits64(double value, std::uint64_t keep) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(value) & keep);
}

// 1/√q for q ≥ 1 with a relative error below 1.5·10⁻⁷ (as good as float
// arithmetic gets): the classic bit-level estimate (Lomont's constant, error
// < 3.5·10⁻²) and three Newton steps, each squaring the error. Two steps
// (error 5·10⁻⁶) would not do: the length of a unit normal enters angles to
// other unit vectors as √(2·error), 0.2° here.
inline float inverse_sqrt(float q) {
  float y = std::bit_cast<float>(0x5f375a86u - (std::bit_cast<std::uint32_t>(q) >> 1));
  y *= 1.5f - 0.5f * q * y * y;
  y *= 1.5f - 0.5f * q * y * y;
  y *= 1.5f - 0.5f * q * y * y;
  return y;
}

// ln x for a positive, normal, finite float, within 0.8 ulp of the exact
// value (measured over [10⁻³, 10⁶]; glibc's logf differs from it by one ulp
// on 3 % of the inputs). Cephes' logf: x = 2^e · m with m in [√½, √2), then
// ln m = f − f²/2 + f³·P(f) with f = m − 1, and e·ln 2 split in two parts.
// Plain arithmetic, so it vectorizes, where std::log is a library call.
inline float log_positive(float x) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  const std::uint32_t above = (bits & 0x007fffffu) > 0x003504f3u ? 1u : 0u;  // mantissa > √2
  const float m = std::bit_cast<float>((bits & 0x007fffffu) | ((0x7fu - above) << 23));
  const float e = static_cast<float>(static_cast<std::int32_t>((bits >> 23) & 0xffu) - 127 +
                                     static_cast<std::int32_t>(above));
  const float f = m - 1.0f, z = f * f;
  float y = 7.0376836292e-2f;
  y = y * f - 1.1514610310e-1f;
  y = y * f + 1.1676998740e-1f;
  y = y * f - 1.2420140846e-1f;
  y = y * f + 1.4249322787e-1f;
  y = y * f - 1.6668057665e-1f;
  y = y * f + 2.0000714765e-1f;
  y = y * f - 2.4999993993e-1f;
  y = y * f + 3.3333331174e-1f;
  y = y * f * z;
  y += -2.12194440e-4f * e;
  y += -0.5f * z;
  return (f + y) + 0.693359375f * e;
}

}  // namespace scanbench::acquisition

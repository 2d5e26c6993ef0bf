// Small helpers that let GCC vectorize loops under the project's portable
// flags (x86-64 baseline, errno-setting math, trapping math). With those
// flags GCC turns a conditional expression on floats back into a branch,
// std::sqrt keeps a branch to the library call that sets errno, and std::log
// is a library call; any of them stops the vectorizer. Bit-mask selects, an
// inverse square root by Newton steps and a logarithm in plain arithmetic
// avoid them.
#pragma once

#include <bit>
#include <cstdint>

// Function multiversioning for the stage's widest vector loops: an AVX2
// clone next to the baseline x86-64 one, chosen once at load time, so the
// binary still runs on any x86-64. Only AVX2, not FMA: without fused
// multiply-adds and with no reductions in these loops, both clones give
// identical results.
// A build may define it empty: the sanitizer build does (clones are chosen by
// an ifunc resolver, which runs before the sanitizer runtime is set up), and
// a build may do so to compare the two.
#ifndef SCANBENCH_VECTOR_CLONES
#if defined(__x86_64__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define SCANBENCH_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#endif
#ifndef SCANBENCH_VECTOR_CLONES
#define SCANBENCH_VECTOR_CLONES
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
// arithmetic gets). The initial estimate works on the float's bits, with the
// constant 0x5f375a86 of C. Lomont, "Fast inverse square root" (2003), within
// 3.5·10⁻² of the exact value; three Newton steps follow, each squaring the
// error. Two steps (error 5·10⁻⁶) would not do: the length of a unit normal
// enters angles to other unit vectors as √(2·error), 0.2° here.
inline float inverse_sqrt(float q) {
  float y = std::bit_cast<float>(0x5f375a86u - (std::bit_cast<std::uint32_t>(q) >> 1));
  y *= 1.5f - 0.5f * q * y * y;
  y *= 1.5f - 0.5f * q * y * y;
  y *= 1.5f - 0.5f * q * y * y;
  return y;
}

// ln x for a positive, normal, finite float, in plain arithmetic so that it
// vectorizes (std::log is a library call). The argument reduction is the
// textbook one (e.g. J.-M. Muller, "Elementary Functions: Algorithms and
// Implementation", range reduction with ln 2 split in two parts):
// x = 2^e · m with m in [√½, √2), and ln x = e · ln 2 + ln m, where e · ln 2
// is added in two parts, 355/512 (exact in a float, so e · 355/512 is too)
// and the small rest, so that the sum keeps its precision for large
// exponents. ln m = 2 artanh s with s = (m − 1)/(m + 1), |s| ≤ 0.172, summed
// as the odd series 2s(1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9): the first term left
// out is below 2·10⁻⁹ of the sum, far under float rounding. Measured on
// every float of [10⁻³, 10⁶]: within 1.3·10⁻⁷ · max(1, |ln x|) of the exact
// value.
inline float log_positive(float x) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  const std::uint32_t above = (bits & 0x007fffffu) > 0x003504f3u ? 1u : 0u;  // mantissa > √2
  const float m = std::bit_cast<float>((bits & 0x007fffffu) | ((0x7fu - above) << 23));
  const float e = static_cast<float>(static_cast<std::int32_t>((bits >> 23) & 0xffu) - 127 +
                                     static_cast<std::int32_t>(above));
  const float s = (m - 1.0f) / (m + 1.0f), z = s * s;
  const float series = 1.0f + z * (1.0f / 3 + z * (1.0f / 5 + z * (1.0f / 7 + z * (1.0f / 9))));
  constexpr float kLn2High = 355.0f / 512.0f, kLn2Low = -2.121944400546906e-4f;
  return (2.0f * s * series + kLn2Low * e) + kLn2High * e;
}

}  // namespace scanbench::acquisition

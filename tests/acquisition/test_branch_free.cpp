// The vectorizable math of acquisition/geometry/branch_free.hpp against the library
// functions in double precision, over the ranges the geometry stage uses.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "acquisition/geometry/branch_free.hpp"

namespace scanbench::acquisition {
namespace {

// The worst error over the floats [low, high], every `stride`-th bit pattern
// and the bounds themselves; `error(x)` is already scaled by its tolerance.
struct Worst {
  double error = 0.0;
  float at = 0.0f;
};

template <typename Error>
Worst worst_over(float low, float high, std::uint32_t stride, Error&& error) {
  Worst worst;
  const auto visit = [&](float x) {
    const double e = error(x);
    if (!(e <= worst.error)) worst = {e, x};  // also catches NaN
  };
  const std::uint32_t first = std::bit_cast<std::uint32_t>(low);
  const std::uint32_t last = std::bit_cast<std::uint32_t>(high);
  for (std::uint32_t bits = first; bits < last; bits += stride) visit(std::bit_cast<float>(bits));
  visit(high);
  return worst;
}

// |log_positive(x) − ln x| / (2.5·10⁻⁷ · max(1, |ln x|)).
double log_error(float x) {
  const double exact = std::log(static_cast<double>(x));
  return std::abs(log_positive(x) - exact) / (2.5e-7 * std::max(1.0, std::abs(exact)));
}

// |inverse_sqrt(q) − 1/√q| / (1.5·10⁻⁷ / √q).
double inverse_sqrt_error(float q) {
  const double exact = 1.0 / std::sqrt(static_cast<double>(q));
  return std::abs(inverse_sqrt(q) - exact) / (1.5e-7 * exact);
}

TEST(BranchFree, LogOfOneIsZeroAndOfPowersOfTwoIsNearlyExact) {
  EXPECT_EQ(log_positive(1.0f), 0.0f);
  for (int e = -9; e <= 19; ++e) {
    const float x = std::ldexp(1.0f, e);
    EXPECT_LE(log_error(x), 1.0) << "x = 2^" << e;
    EXPECT_NEAR(log_positive(x), e * std::numbers::ln2, 2.5e-7 * std::max(1, std::abs(e)));
  }
}

TEST(BranchFree, LogIsAccurateOverTheRangesOfAScan) {
  // Every 17th float of [10⁻³, 10⁶] (about 15 million), and every float
  // around the mantissa's switch at √2, where the reduction changes exponent.
  const Worst sampled = worst_over(1e-3f, 1e6f, 17, log_error);
  EXPECT_LE(sampled.error, 1.0) << "at x = " << sampled.at;
  for (const float binade : {1e-3f, 0.5f, 1.0f, 8.0f, 1e5f}) {
    const float root2 = std::sqrt(2.0f) * std::ldexp(1.0f, std::ilogb(binade));
    const Worst near = worst_over(root2 * (1.0f - 1e-4f), root2 * (1.0f + 1e-4f), 1, log_error);
    EXPECT_LE(near.error, 1.0) << "at x = " << near.at;
  }
}

TEST(BranchFree, InverseSqrtOfSquaresIsTheReciprocalRoot) {
  for (const float root : {1.0f, 2.0f, 3.0f, 10.0f, 1000.0f}) {
    EXPECT_NEAR(inverse_sqrt(root * root), 1.0f / root, 1.5e-7f / root) << "root " << root;
  }
}

TEST(BranchFree, InverseSqrtIsAccurateOverOneToAHundredMillion) {
  // Scaling q by 4 scales every intermediate by a power of two, exactly, so
  // the relative error repeats with period 4: every float of [1, 4] covers
  // them all (the worst, 1.48·10⁻⁷, is near 3.89). A sample of the rest.
  const Worst period = worst_over(1.0f, 4.0f, 1, inverse_sqrt_error);
  EXPECT_LE(period.error, 1.0) << "at q = " << period.at;
  const Worst sampled = worst_over(4.0f, 1e8f, 101, inverse_sqrt_error);
  EXPECT_LE(sampled.error, 1.0) << "at q = " << sampled.at;
}

}  // namespace
}  // namespace scanbench::acquisition

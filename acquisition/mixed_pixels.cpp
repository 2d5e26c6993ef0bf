#include "acquisition/mixed_pixels.hpp"

#include <cmath>
#include <cstddef>

#include "acquisition/parallel.hpp"

namespace scanbench::acquisition {
namespace {

// Ranges with a border of two pixels, −1 where there is no valid return, so
// the line tests below need no bounds checks.
struct PaddedRanges {
  static constexpr int kPad = 2;
  int stride;
  std::vector<float> values;

  explicit PaddedRanges(const Scan& scan)
      : stride(scan.columns + 2 * kPad),
        values(static_cast<std::size_t>(scan.rows + 2 * kPad) * stride, -1.0f) {
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::size_t i = scan.index(row, col);
        if (scan.valid[i]) values[at(row, col)] = scan.range_m[i];
      }
    }
  }
  std::size_t at(int row, int col) const {
    return static_cast<std::size_t>(row + kPad) * stride + (col + kPad);
  }
};

// The test of detect_mixed_pixels along one grid line with step `step` in
// the padded array.
bool mixed_along(const float* c, std::ptrdiff_t step, float threshold) {
  const float a1 = c[-step], a2 = c[-2 * step], b1 = c[step], b2 = c[2 * step];
  if (a1 < 0 || a2 < 0 || b1 < 0 || b2 < 0) return false;
  const float centre = *c;
  if (!((a1 < centre && centre < b1) || (b1 < centre && centre < a1))) return false;
  const float miss_a = centre - (2.0f * a1 - a2);  // off the continuation of side a
  const float miss_b = centre - (2.0f * b1 - b2);
  return std::abs(miss_a) > threshold && std::abs(miss_b) > threshold && miss_a * miss_b < 0.0f;
}

}  // namespace

std::vector<std::uint8_t> detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings) {
  std::vector<std::uint8_t> mixed(scan.pixel_count(), 0);
  const PaddedRanges padded(scan);
  const std::ptrdiff_t s = padded.stride;
  const std::ptrdiff_t steps[4] = {1, s, s + 1, s - 1};  // row, column, both diagonals
  parallel_for_index(scan.rows, settings.threads, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      const float* centre = padded.values.data() + padded.at(row, col);
      if (*centre < 0) continue;
      const auto threshold =
          static_cast<float>(settings.mixed_pixel_sigmas *
                             (settings.range_noise_m + settings.range_noise_per_m * *centre));
      bool is_mixed = false;
      for (const std::ptrdiff_t step : steps)
        is_mixed = is_mixed || mixed_along(centre, step, threshold);
      mixed[scan.index(row, col)] = is_mixed;
    }
  });
  return mixed;
}

}  // namespace scanbench::acquisition

#include "acquisition/geometry/mixed_pixels.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include "acquisition/geometry/branch_free.hpp"
#include "core/parallel.hpp"

namespace scanbench::acquisition {
namespace {

// Rows per task: the block's padded copy (block + 4 rows) stays in cache.
constexpr int kBlockRows = 16;

// Ranges [m] of rows [row_begin − 2, row_end + 2) with a border of two pixels,
// −1 where there is no valid return, so the line tests below need no bounds
// checks and no branches.
struct PaddedBlock {
  static constexpr int kPad = 2;
  int row_begin, stride;
  std::vector<float> values;

  PaddedBlock(const Scan& scan, int begin, int end)
      : row_begin(begin),
        stride(scan.columns + 2 * kPad),
        values(static_cast<std::size_t>(end - begin + 2 * kPad) * stride, -1.0f) {
    for (int row = std::max(0, begin - kPad); row < std::min(scan.rows, end + kPad); ++row) {
      float* out = values.data() + at(row, 0);
      const std::size_t i = scan.index(row, 0);
      for (int col = 0; col < scan.columns; ++col)
        out[col] = scan.valid[i + col] ? scan.range_m[i + col] : -1.0f;
    }
  }
  std::size_t at(int row, int col) const {
    return static_cast<std::size_t>(row - row_begin + kPad) * stride + (col + kPad);
  }
};

// The test of detect_mixed_pixels along one grid line, on the centre's range
// and its neighbours' at −2, −1 (side a) and +1, +2 (side b), all in metres
// (−1: no return), and the threshold [m]. Bitwise operators, no early exits:
// the column loop below vectorizes.
inline bool mixed_along(float centre, float a2, float a1, float b1, float b2, float threshold_m) {
  const bool present = (a1 >= 0.0f) & (a2 >= 0.0f) & (b1 >= 0.0f) & (b2 >= 0.0f);
  const bool between = ((a1 < centre) & (centre < b1)) | ((b1 < centre) & (centre < a1));
  const float miss_a = centre - (2.0f * a1 - a2);  // off the continuation of side a
  const float miss_b = centre - (2.0f * b1 - b2);
  return present & between & (std::abs(miss_a) > threshold_m) & (std::abs(miss_b) > threshold_m) &
         (miss_a * miss_b < 0.0f);
}

// One row's flags into out; the threshold at range r [m] is sigma0_m +
// (sigma1 + sigma2 · r) · r.
SCANBENCH_VECTOR_CLONES void detect_row(const PaddedBlock& block, int row, int columns,
                                        float sigma0_m, float sigma1, float sigma2,
                                        std::uint8_t* out) {
  const std::ptrdiff_t s = block.stride;
  const float* p = block.values.data() + block.at(row, 0);
  for (int col = 0; col < columns; ++col) {
    const float* c = p + col;
    const float centre = *c;
    const float threshold_m = sigma0_m + (sigma1 + sigma2 * centre) * centre;
    const bool mixed =
        mixed_along(centre, c[-2], c[-1], c[1], c[2], threshold_m) |
        mixed_along(centre, c[-2 * s], c[-s], c[s], c[2 * s], threshold_m) |
        mixed_along(centre, c[-2 * s - 2], c[-s - 1], c[s + 1], c[2 * s + 2], threshold_m) |
        mixed_along(centre, c[-2 * s + 2], c[-s + 1], c[s - 1], c[2 * s - 2], threshold_m);
    out[col] = (centre >= 0.0f) & mixed;
  }
}

}  // namespace

void detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings,
                         std::span<std::uint8_t> mixed) {
  assert(check_consistency(scan).empty() && mixed.size() == scan.pixel_count() &&
         "a consistent scan and one output per pixel");
  const auto sigma0_m =
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_m);
  const auto sigma1 =
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_per_m);
  const auto sigma2 =
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_per_m2);
  const int blocks = (scan.rows + kBlockRows - 1) / kBlockRows;
  core::parallel_for_index(blocks, settings.threads, [&](int b) {
    const int begin = b * kBlockRows, end = std::min(scan.rows, begin + kBlockRows);
    const PaddedBlock block(scan, begin, end);
    for (int row = begin; row < end; ++row)
      detect_row(block, row, scan.columns, sigma0_m, sigma1, sigma2,
                 mixed.data() + scan.index(row, 0));
  });
}

}  // namespace scanbench::acquisition

#include "acquisition/geometry/mixed_pixels.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include "acquisition/geometry/branch_free.hpp"
#include "core/parallel.hpp"

namespace scanbench::acquisition {
namespace {

// Rows per task: the block's padded copy (block + 6 rows) stays in cache.
constexpr int kBlockRows = 16;

// Ranges [m] of rows [row_begin − 3, row_end + 3) with a border of three pixels,
// −1 where there is no valid return, so the line tests below need no bounds
// checks and no branches.
struct PaddedBlock {
  static constexpr int kPad = 3;
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

// The continuation of one side to the centre from its ranges at distance
// 1, 2 and 3 (−1: no return): the least-squares line through the three, or
// through the first two where the third has no return.
inline float continuation(float r1, float r2, float r3) {
  const float three = (4.0f * r1 + r2 - 2.0f * r3) * (1.0f / 3.0f);
  return r3 >= 0.0f ? three : 2.0f * r1 - r2;
}

// The thresholds of one pixel [m]: how far off both continuations, and how
// far apart they must be.
struct Thresholds {
  float miss_m, gap_m;
};

// The test of detect_mixed_pixels along one grid line, on the centre's range
// and its neighbours' at −3, −2, −1 (side a) and +1, +2, +3 (side b), all in
// metres (−1: no return). Bitwise operators, no early exits: the column loop
// below vectorizes.
inline bool mixed_along(float centre, const float (&a)[3], const float (&b)[3], Thresholds t) {
  const bool present = (a[0] >= 0.0f) & (a[1] >= 0.0f) & (b[0] >= 0.0f) & (b[1] >= 0.0f);
  const bool between = ((a[0] < centre) & (centre < b[0])) | ((b[0] < centre) & (centre < a[0]));
  const float on_a = continuation(a[0], a[1], a[2]), on_b = continuation(b[0], b[1], b[2]);
  const float miss_a = centre - on_a, miss_b = centre - on_b;
  return present & between & (std::abs(miss_a) > t.miss_m) & (std::abs(miss_b) > t.miss_m) &
         (miss_a * miss_b < 0.0f) & (std::abs(on_a - on_b) > t.gap_m);
}

// The test along the line through c with step s (in floats of the block).
inline bool mixed_along_step(const float* c, std::ptrdiff_t s, Thresholds t) {
  const float a[3] = {c[-s], c[-2 * s], c[-3 * s]}, b[3] = {c[s], c[2 * s], c[3 * s]};
  return mixed_along(*c, a, b, t);
}

// Per-pixel thresholds: σ(r) = sigma0_m + (sigma1 + sigma2 · r) · r times
// the sigmas, at least `relative` · r; the gap `jump` · r.
struct ThresholdModel {
  float sigma0_m, sigma1, sigma2, relative, jump;

  Thresholds at(float range_m) const {
    const float noise_m = sigma0_m + (sigma1 + sigma2 * range_m) * range_m;
    return {std::max(noise_m, relative * range_m), jump * range_m};
  }
};

// One row's flags into out.
SCANBENCH_VECTOR_CLONES void detect_row(const PaddedBlock& block, int row, int columns,
                                        const ThresholdModel& model, std::uint8_t* out) {
  const std::ptrdiff_t s = block.stride;
  const float* p = block.values.data() + block.at(row, 0);
  for (int col = 0; col < columns; ++col) {
    const float* c = p + col;
    const Thresholds t = model.at(*c);
    const bool mixed = mixed_along_step(c, 1, t) | mixed_along_step(c, s, t) |
                       mixed_along_step(c, s + 1, t) | mixed_along_step(c, s - 1, t);
    out[col] = (*c >= 0.0f) & mixed;
  }
}

}  // namespace

void detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings,
                         std::span<std::uint8_t> mixed) {
  assert(check_consistency(scan).empty() && mixed.size() == scan.pixel_count() &&
         "a consistent scan and one output per pixel");
  const ThresholdModel model{
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_m),
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_per_m),
      static_cast<float>(settings.mixed_pixel_sigmas * settings.range_noise.noise_per_m2),
      static_cast<float>(settings.mixed_pixel_relative),
      static_cast<float>(settings.depth_jump_relative)};
  const int blocks = (scan.rows + kBlockRows - 1) / kBlockRows;
  core::parallel_for_index(blocks, settings.threads, [&](int b) {
    const int begin = b * kBlockRows, end = std::min(scan.rows, begin + kBlockRows);
    const PaddedBlock block(scan, begin, end);
    for (int row = begin; row < end; ++row)
      detect_row(block, row, scan.columns, model, mixed.data() + scan.index(row, 0));
  });
}

}  // namespace scanbench::acquisition

// Moments of a masked value over a square window around every pixel, in
// constant time per pixel whatever the window size: running sums along rows,
// then along columns (the separable form of an integral image, which keeps
// every sum local and so free of the cancellation a global integral image
// suffers in float or double).
//
// For pixel (row, col) and window offsets dx = c − col, dy = r − row in
// [−k, k], with mask m and value v:
//   n   = Σ m          sx  = Σ m dx      sy  = Σ m dy
//   sxx = Σ m dx²      sxy = Σ m dx dy   syy = Σ m dy²
//   sv  = Σ m v        sxv = Σ m dx v    syv = Σ m dy v
// Pixels outside the grid count as m = 0.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace scanbench::acquisition {

struct WindowMoments {
  float n, sx, sy, sxx, sxy, syy, sv, sxv, syv;
};

// Hands the moments of pixels (row, col_begin … col_end − 1) to `visit`, every
// row once per column block, blocks in parallel (so `visit` must only touch
// its own pixels). Nothing of grid size is kept beyond one row of running
// sums per block. `mask` is 0 or 1 per pixel, `value` is read only where the
// mask is 1. `threads` as in the Settings structs (0 = all cores); the
// moments do not depend on it. Asserts the spans hold rows × columns entries
// and radius ≥ 1.
using MomentsVisitor =
    std::function<void(int row, int col_begin, int col_end, const WindowMoments* moments)>;
void visit_window_moments(int rows, int columns, int radius, std::span<const std::uint8_t> mask,
                          std::span<const float> value, int threads, const MomentsVisitor& visit);

// All moments at once (rows × columns, row-major), for tests and small grids.
std::vector<WindowMoments> window_moments(int rows, int columns, int radius,
                                          std::span<const std::uint8_t> mask,
                                          std::span<const float> value, int threads);

// Number of set pixels of `mask` in the window around every pixel (the n of
// window_moments alone, for flag maps). Same contract as window_moments.
std::vector<std::uint16_t> window_counts(int rows, int columns, int radius,
                                         std::span<const std::uint8_t> mask, int threads);

}  // namespace scanbench::acquisition

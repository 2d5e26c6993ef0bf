// Least-squares slopes of a value over square pixel windows, in constant time
// per pixel whatever the window size: the window moments come from integral
// images (summed-area tables; Crow, SIGGRAPH 1984), four look-ups per moment.
//
// Only *clean* windows are fitted — every pixel inside the grid and marked
// clean — and a clean window is full and symmetric, so for window offsets
// dx = c − col, dy = r − row in [−k, k] the plane fit v ≈ a + b·dx + c·dy
// decouples (Σdx = Σdy = Σdx·dy = 0):
//   a = Σ v / (2k+1)²,   b = Σ dx·v / Σ dx²,   c = Σ dy·v / Σ dy²,
//   Σ dx² = Σ dy² = (2k+1)² k(k+1) / 3,
// and needs three moments of v (Σv, Σx·v, Σy·v) and the count of unclean
// pixels. Each tile of the grid builds its own integral images, in double
// precision and tile-local coordinates, so every sum stays small (no
// cancellation of a global integral image) and the result depends on the grid
// size only, never on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "acquisition/geometry/row_band.hpp"

namespace scanbench::acquisition {

// The fit of the widest clean window around one pixel.
struct WindowSlope {
  float mean = 0.0f;        // the window's mean value
  float per_column = 0.0f;  // d value / d col
  float per_row = 0.0f;     // d value / d row
  std::uint16_t used = 0;   // pixels in the window, (2k + 1)²; 0 = no clean window
};

// The fits of one row segment as parallel arrays, one entry per pixel (the
// loops that consume them vectorize).
struct WindowSlopeRow {
  const float* mean;
  const float* per_column;
  const float* per_row;
  const std::uint16_t* used;
};

// Hands the slopes of pixels (row, col_begin … col_end − 1) to `visit`, tile
// by tile, tiles in parallel (so `visit` must only touch its own pixels);
// every pixel is visited exactly once. A pixel takes the first radius of
// `radii` (widest first) at which its window is clean; pixels that are not
// clean themselves get used = 0. `clean` is 0 or 1 per pixel, `value` is read
// only where clean is 1. `threads` as in the Settings structs (0 = all
// cores). Asserts the spans hold rows × columns entries and the radii are
// descending, ≥ 1 and ≤ 127 (so `used` fits 16 bits).
//
// With a `band`, the spans hold rows [band.first_row, band.first_row + rows)
// of a grid of band.rows rows, and only grid rows [band.begin, band.end)
// are visited, `row` counting the held rows: the tiles are the whole
// grid's, so a band whose limits are window_tile_row_cuts gets the slopes
// of the whole grid bit for bit, provided it holds the rows of its windows
// (radii[0] beyond its limits, or the grid's end).
using SlopeVisitor =
    std::function<void(int row, int col_begin, int col_end, const WindowSlopeRow& slopes)>;
void visit_window_slopes(int rows, int columns, std::span<const int> radii,
                         std::span<const std::uint8_t> clean, std::span<const float> value,
                         int threads, const SlopeVisitor& visit,
                         std::optional<RowBand> band = std::nullopt);

// The rows at which the tiles of a grid of `rows` rows begin, and `rows`:
// ascending, from 0.
std::vector<int> window_tile_row_cuts(int rows);

// All slopes at once (rows × columns, row-major), for tests and small grids.
std::vector<WindowSlope> window_slopes(int rows, int columns, std::span<const int> radii,
                                       std::span<const std::uint8_t> clean,
                                       std::span<const float> value, int threads);

}  // namespace scanbench::acquisition

#include "acquisition/geometry/window_moments.hpp"

#include <algorithm>
#include <cassert>
#include <cstddef>

#include "acquisition/geometry/branch_free.hpp"
#include "core/parallel.hpp"

namespace scanbench::acquisition {
namespace {

// Tile size targets: a tile's ring of integral rows (2k + 2 rows of
// 28 bytes per column) stays in a core's L2 cache, the halo of k pixels on
// every side costs little next to the tile, and a 3600 × 900 scan gives
// 32 tiles for the threads to share.
constexpr int kTileColumns = 512;
constexpr int kTileRows = 256;

struct Tile {
  int row_begin, row_end, col_begin, col_end;
};

// The row tiles' limits: the grid's rows split evenly into tiles of at most
// kTileRows; the split depends on the grid size alone, so results do not
// depend on the threads.
std::vector<int> row_cuts(int rows) {
  const int row_tiles = (rows + kTileRows - 1) / kTileRows;
  std::vector<int> cuts = {0};
  for (int i = 1; i <= row_tiles; ++i) cuts.push_back(rows * i / row_tiles);
  return cuts;
}

// The tiles of `band`'s rows, in held rows: the whole grid's row tiles
// (row_cuts) that lie in [band.begin, band.end), cut evenly across.
std::vector<Tile> make_tiles(const RowBand& band, int columns) {
  const std::vector<int> cuts = row_cuts(band.rows);
  const int col_tiles = (columns + kTileColumns - 1) / kTileColumns;
  std::vector<Tile> tiles;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if (cuts[i] < band.begin || cuts[i + 1] > band.end || cuts[i] == cuts[i + 1]) continue;
    for (int j = 0; j < col_tiles; ++j) {
      tiles.push_back({cuts[i] - band.first_row, cuts[i + 1] - band.first_row,
                       columns * j / col_tiles, columns * (j + 1) / col_tiles});
    }
  }
  return tiles;
}

struct Grid {
  int rows, columns;
  const std::uint8_t* clean;
  const float* value;
};

// Integral images over one tile grown by `halo` pixels on every side (the
// "region"; pixels outside the grid are unclean), in region coordinates
// (y, x). Integral row j, entry x, sums region rows [0, j) and columns
// [0, x). Only the 2·halo + 2 rows the current output row needs are kept.
// Not copyable or movable: v_, xv_ and yv_ point into its own moments_.
class IntegralRing {
 public:
  IntegralRing(const Grid& grid, const Tile& tile, int halo)
      : grid_(grid),
        row0_(tile.row_begin - halo),
        col0_(tile.col_begin - halo),
        width_(tile.col_end - tile.col_begin + 2 * halo),
        stride_(width_ + 1),
        slots_(2 * halo + 2),
        unclean_(static_cast<std::size_t>(slots_) * stride_, 0),
        moments_(3 * unclean_.size(), 0.0),
        v_(moments_.data()),
        xv_(v_ + unclean_.size()),
        yv_(xv_ + unclean_.size()),
        row_unclean_(static_cast<std::size_t>(width_)),
        row_value_(static_cast<std::size_t>(width_)) {}
  IntegralRing(const IntegralRing&) = delete;
  IntegralRing& operator=(const IntegralRing&) = delete;
  IntegralRing(IntegralRing&&) = delete;
  IntegralRing& operator=(IntegralRing&&) = delete;

  // Makes integral rows up to `j` available (slot 0 is row 0: all zeros).
  void extend_to(int j) {
    while (count_ <= j) push();
  }

  // The integral rows that bound the windows of radius k around region row
  // y, resolved once per row (a ring slot costs a division).
  struct Bounds {
    const std::int32_t *top_unclean, *bottom_unclean;
    const double *top_v, *bottom_v, *top_xv, *bottom_xv, *top_yv, *bottom_yv;
  };
  Bounds bounds(int y, int k) const {
    const std::size_t t = slot(y - k), b = slot(y + k + 1);
    return {unclean_.data() + t,
            unclean_.data() + b,
            v_ + t,
            v_ + b,
            xv_ + t,
            xv_ + b,
            yv_ + t,
            yv_ + b};
  }

 private:
  std::size_t slot(int j) const { return static_cast<std::size_t>(j % slots_) * stride_; }

  // Region row `y` as unclean flags and values (0 where unclean).
  void load_region_row(int y) {
    const int row = row0_ + y;
    std::fill(row_unclean_.begin(), row_unclean_.end(), 1);
    std::fill(row_value_.begin(), row_value_.end(), 0.0f);
    if (row < 0 || row >= grid_.rows) return;
    // Grid index of region column x: first + x, ≥ 0 for x ≥ x_begin (col0_
    // is negative on the tiles at the grid's left border).
    const std::ptrdiff_t first = static_cast<std::ptrdiff_t>(row) * grid_.columns + col0_;
    const int x_begin = std::max(0, -col0_), x_end = std::min(width_, grid_.columns - col0_);
    for (int x = x_begin; x < x_end; ++x) {  // branch-free: cleanness is data, it vectorizes
      const std::uint8_t clean = grid_.clean[first + x];
      row_unclean_[x] = clean == 0;
      row_value_[x] = select_bits(grid_.value[first + x], all_bits(clean != 0));
    }
  }

  // Integral row count_ = integral row count_ − 1 + the prefix sums of
  // region row count_ − 1.
  void push() {
    if (count_ > 0) {
      const int y = count_ - 1;
      load_region_row(y);
      const std::size_t dst = slot(count_) + 1, src = slot(count_ - 1) + 1;
      std::int32_t pu = 0;
      double pv = 0.0, pxv = 0.0;
      for (int x = 0; x < width_; ++x) {
        const double v = row_value_[x];
        pu += row_unclean_[x], pv += v, pxv += x * v;
        unclean_[dst + x] = unclean_[src + x] + pu;
        v_[dst + x] = v_[src + x] + pv;
        xv_[dst + x] = xv_[src + x] + pxv;
        yv_[dst + x] = yv_[src + x] + y * pv;
      }
    }
    ++count_;
  }

  Grid grid_;
  int row0_, col0_, width_, stride_, slots_;
  int count_ = 0;
  std::vector<std::int32_t> unclean_;
  std::vector<double> moments_;  // the integral images of v, x·v and y·v, one after another
  double *v_, *xv_, *yv_;
  std::vector<std::int32_t> row_unclean_;
  std::vector<float> row_value_;
};

// 1 / Σ dx² of a full window of radius k.
double inverse_sxx(int k) {
  const double side = 2.0 * k + 1.0;
  return 3.0 / (side * side * k * (k + 1.0));
}

// The sum over columns [left, right) between two integral rows.
template <typename T>
T box(const T* top, const T* bottom, int left, int right) {
  return (bottom[right] - bottom[left]) - (top[right] - top[left]);
}

// One row segment's fits as parallel arrays.
struct SlopeBuffers {
  std::vector<float> mean, per_column, per_row;
  std::vector<std::uint16_t> used;

  explicit SlopeBuffers(std::size_t n) : mean(n), per_column(n), per_row(n), used(n) {}
  WindowSlopeRow row() const {
    return {mean.data(), per_column.data(), per_row.data(), used.data()};
  }
};

// The count of unclean pixels, Σ v and the centred moments Σ dx·v, Σ dy·v of
// the window of radius k around region pixel (y, x); `b` bounds its rows.
struct Window {
  std::int32_t unclean;
  double sv, sxv, syv;
};

inline Window window_at(const IntegralRing::Bounds& b, int y, int x, int k) {
  const int left = x - k, right = x + k + 1;
  // Moments about the window's centre: Σ dx·v = Σ x·v − x·Σ v, likewise dy.
  const double sv = box(b.top_v, b.bottom_v, left, right);
  return {box(b.top_unclean, b.bottom_unclean, left, right), sv,
          box(b.top_xv, b.bottom_xv, left, right) - x * sv,
          box(b.top_yv, b.bottom_yv, left, right) - y * sv};
}

std::uint16_t window_pixels(int k) {
  return static_cast<std::uint16_t>((2 * k + 1) * (2 * k + 1));
}

// The fit at radius k of every pixel of a row segment, x = x0 … x0 + n − 1
// in region coordinates (y its row): used = (2k + 1)² where the pixel and its
// window are clean, else 0. Branch-free, so that it vectorizes: most pixels
// stop at the widest radius.
SCANBENCH_VECTOR_CLONES void fit_radius(int n, int x0, int y, int k, double inverse,
                                        const IntegralRing::Bounds& b,
                                        const std::uint8_t* __restrict clean,
                                        float* __restrict mean, float* __restrict per_column,
                                        float* __restrict per_row, std::uint16_t* __restrict used) {
  const std::uint16_t full = window_pixels(k);
  const double inverse_count = 1.0 / full;
  for (int j = 0; j < n; ++j) {
    const Window w = window_at(b, y, x0 + j, k);
    const std::uint32_t ok = all_bits((clean[j] != 0) & (w.unclean == 0));
    mean[j] = select_bits(static_cast<float>(w.sv * inverse_count), ok);
    per_column[j] = select_bits(static_cast<float>(w.sxv * inverse), ok);
    per_row[j] = select_bits(static_cast<float>(w.syv * inverse), ok);
    used[j] = static_cast<std::uint16_t>(full & ok);
  }
}

// The narrower radii, widest first, for one clean pixel the widest left
// without a window.
void fit_narrower(std::span<const IntegralRing::Bounds> bounds, std::span<const int> radii,
                  std::span<const double> inverse, int y, int x, SlopeBuffers& out, std::size_t j) {
  for (std::size_t r = 1; r < radii.size(); ++r) {
    const Window w = window_at(bounds[r], y, x, radii[r]);
    if (w.unclean != 0) continue;
    out.mean[j] = static_cast<float>(w.sv / window_pixels(radii[r]));
    out.per_column[j] = static_cast<float>(w.sxv * inverse[r]);
    out.per_row[j] = static_cast<float>(w.syv * inverse[r]);
    out.used[j] = window_pixels(radii[r]);
    return;
  }
}

void visit_tile(const Grid& grid, const Tile& tile, std::span<const int> radii,
                std::span<const double> inverse, const SlopeVisitor& visit) {
  const int halo = radii.front();
  IntegralRing ring(grid, tile, halo);
  SlopeBuffers out(static_cast<std::size_t>(tile.col_end - tile.col_begin));
  std::vector<IntegralRing::Bounds> bounds(radii.size());
  for (int row = tile.row_begin; row < tile.row_end; ++row) {
    const int y = row - tile.row_begin + halo;
    ring.extend_to(y + halo + 1);
    for (std::size_t r = 0; r < radii.size(); ++r) bounds[r] = ring.bounds(y, radii[r]);
    const std::size_t offset = static_cast<std::size_t>(row) * grid.columns;
    const int n = tile.col_end - tile.col_begin;
    // Widest radius for the whole segment, then the narrower ones for the
    // clean pixels it left without a window.
    fit_radius(n, halo, y, radii[0], inverse[0], bounds[0], grid.clean + offset + tile.col_begin,
               out.mean.data(), out.per_column.data(), out.per_row.data(), out.used.data());
    for (int j = 0; j < n; ++j) {
      if (out.used[j] == 0 && grid.clean[offset + tile.col_begin + j])
        fit_narrower(bounds, radii, inverse, y, halo + j, out, static_cast<std::size_t>(j));
    }
    visit(row, tile.col_begin, tile.col_end, out.row());
  }
}

}  // namespace

std::vector<int> window_tile_row_cuts(int rows) {
  return row_cuts(rows);
}

void visit_window_slopes(int rows, int columns, std::span<const int> radii,
                         std::span<const std::uint8_t> clean, std::span<const float> value,
                         int threads, const SlopeVisitor& visit, std::optional<RowBand> band) {
  assert(clean.size() == static_cast<std::size_t>(rows) * columns && value.size() == clean.size() &&
         !radii.empty() && "spans of rows × columns, radii");
  assert(std::is_sorted(radii.rbegin(), radii.rend()) && radii.back() >= 1 &&
         radii.front() <= 127 && "radii descending in [1, 127]");
  std::vector<double> inverse(radii.size());
  std::transform(radii.begin(), radii.end(), inverse.begin(), inverse_sxx);
  const Grid grid{rows, columns, clean.data(), value.data()};
  if (!band) band = RowBand::whole(rows);
  assert(band->first_row >= 0 && band->first_row + rows <= band->rows &&
         band->begin >= band->first_row && band->end <= band->first_row + rows &&
         "the band's computed rows are held");
  const std::vector<Tile> tiles = make_tiles(*band, columns);
  core::parallel_for_index(static_cast<int>(tiles.size()), threads,
                           [&](int t) { visit_tile(grid, tiles[t], radii, inverse, visit); });
}

std::vector<WindowSlope> window_slopes(int rows, int columns, std::span<const int> radii,
                                       std::span<const std::uint8_t> clean,
                                       std::span<const float> value, int threads) {
  std::vector<WindowSlope> result(static_cast<std::size_t>(rows) * columns);
  visit_window_slopes(
      rows, columns, radii, clean, value, threads,
      [&](int row, int begin, int end, const WindowSlopeRow& slopes) {
        WindowSlope* out = result.data() + static_cast<std::size_t>(row) * columns;
        for (int j = 0; j < end - begin; ++j)
          out[begin + j] = {slopes.mean[j], slopes.per_column[j], slopes.per_row[j],
                            slopes.used[j]};
      });
  return result;
}

}  // namespace scanbench::acquisition

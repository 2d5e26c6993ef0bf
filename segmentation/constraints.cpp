#include "segmentation/constraints.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>

namespace scanbench::segmentation {

namespace {

void mark(const GridShape& shape, long long row, long long col, std::uint8_t value,
          std::vector<std::uint8_t>& mask) {
  if (row < 0 || row >= shape.rows) return;
  if (const std::optional<int> c = shape.column(col)) {
    mask[shape.index(static_cast<int>(row), *c)] = value;
  }
}

// The columns whose centres lie in [x_begin, x_end) on one row.
void fill_span(const GridShape& shape, int row, double x_begin, double x_end, std::uint8_t value,
               std::vector<std::uint8_t>& mask) {
  auto first = static_cast<long long>(std::ceil(x_begin));
  auto last = static_cast<long long>(std::ceil(x_end)) - 1;
  if (shape.wraps) {
    last = std::min(last, first + shape.columns - 1);  // one full turn covers every column
  } else {
    first = std::max(first, 0LL);
    last = std::min(last, static_cast<long long>(shape.columns) - 1);
  }
  for (long long col = first; col <= last; ++col) mark(shape, row, col, value, mask);
}

void check_vertices(const GridShape& shape, const Polyline& line,
                    const std::vector<std::uint8_t>& mask) {
  assert(mask.size() == shape.pixel_count() && "mask of another grid");
  assert(std::all_of(line.begin(), line.end(),
                     [&](const Eigen::Vector2d& v) { return within_reach(shape, v); }) &&
         "vertex not finite or more than a grid away from it");
  (void)shape, (void)line, (void)mask;
}

}  // namespace

GridPixel nearest_pixel(const Eigen::Vector2d& xy) {
  assert(xy.allFinite() && "a finite image point");
  const auto index = [](double v) {
    return static_cast<int>(std::llround(std::clamp(v, -1.0, 1e9)));
  };
  return {index(xy.y()), index(xy.x())};
}

bool within_reach(const GridShape& shape, const Eigen::Vector2d& v) {
  return v.allFinite() && v.x() >= -shape.columns && v.x() <= 2.0 * shape.columns &&
         v.y() >= -shape.rows && v.y() <= 2.0 * shape.rows;
}

void fill_polygon(const GridShape& shape, const Polyline& polygon, std::uint8_t value,
                  std::vector<std::uint8_t>& mask) {
  check_vertices(shape, polygon, mask);
  if (polygon.size() < 3) return;
  double low = polygon[0].y(), high = polygon[0].y();
  for (const Eigen::Vector2d& v : polygon) low = std::min(low, v.y()), high = std::max(high, v.y());
  const int first_row =
      static_cast<int>(std::clamp(std::ceil(low), 0.0, static_cast<double>(shape.rows)));
  const int last_row =
      static_cast<int>(std::clamp(std::floor(high), -1.0, static_cast<double>(shape.rows - 1)));
  std::vector<double> crossings;
  for (int row = first_row; row <= last_row; ++row) {
    crossings.clear();
    const double y = row;
    for (std::size_t k = 0; k < polygon.size(); ++k) {
      const Eigen::Vector2d& a = polygon[k];
      const Eigen::Vector2d& b = polygon[(k + 1) % polygon.size()];
      // Half-open in y, so a vertex on the row counts once.
      if ((a.y() <= y) == (b.y() <= y)) continue;
      crossings.push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t k = 0; k + 1 < crossings.size(); k += 2) {
      fill_span(shape, row, crossings[k], crossings[k + 1], value, mask);
    }
  }
}

void draw_barrier(const GridShape& shape, const Polyline& barrier, std::uint8_t value,
                  std::vector<std::uint8_t>& mask) {
  check_vertices(shape, barrier, mask);
  if (barrier.empty()) return;
  const auto nearest = [](double v) { return static_cast<long long>(std::llround(v)); };
  long long x = nearest(barrier[0].x()), y = nearest(barrier[0].y());
  mark(shape, y, x, value, mask);
  for (std::size_t k = 1; k < barrier.size(); ++k) {
    const long long x1 = nearest(barrier[k].x()), y1 = nearest(barrier[k].y());
    const long long dx = std::llabs(x1 - x), dy = std::llabs(y1 - y);
    const long long sx = x1 > x ? 1 : -1, sy = y1 > y ? 1 : -1;
    // Step along x while the line's crossing of the next column comes before
    // its crossing of the next row: (½ + ix) / dx < (½ + iy) / dy.
    for (long long ix = 0, iy = 0; ix < dx || iy < dy;) {
      if (iy == dy || (ix < dx && (2 * ix + 1) * dy < (2 * iy + 1) * dx)) {
        x += sx, ++ix;
      } else {
        y += sy, ++iy;
      }
      mark(shape, y, x, value, mask);
    }
  }
}

std::vector<std::uint8_t> open_pixels(const SegmentationGrid& grid, const Constraints& constraints,
                                      std::span<const std::uint8_t> taken) {
  const GridShape& shape = grid.shape;
  assert((taken.empty() || taken.size() == shape.pixel_count()) && "taken mask of another grid");
  std::vector<std::uint8_t> open;
  if (constraints.lasso.size() >= 3) {
    open.assign(shape.pixel_count(), 0);
    fill_polygon(shape, constraints.lasso, 1, open);
  } else {
    open.assign(shape.pixel_count(), 1);
  }
  for (const Polyline& barrier : constraints.barriers) draw_barrier(shape, barrier, 0, open);
  for (std::size_t i = 0; i < open.size(); ++i) {
    const bool free = taken.empty() || taken[i] == 0;
    open[i] = static_cast<std::uint8_t>(open[i] && grid.usable[i] && free);
  }
  return open;
}

}  // namespace scanbench::segmentation

// The fallback normal of the geometry stage (scan_geometry.hpp): a covariance
// fit of the 3D points in a small grid window around a pixel, leaving out the
// neighbours across a depth discontinuity. Used where no clean log-range
// window exists (next to a discontinuity, an invalid region or the grid's
// border) and on grids with per-pixel directions.
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <cstdint>
#include <span>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Unit viewing directions without trigonometry per pixel: a spherical scan's
// from per-column and per-row tables, a per-pixel grid's from the scan (a view:
// the scan must outlive it).
struct GridDirections {
  std::vector<float> cos_az, sin_az, cos_el, sin_el;  // spherical scans only
  std::span<const Eigen::Vector3f> per_pixel;         // per-pixel grids only, rows × columns
  int columns = 0;

  // Of `scan`'s pixels; where `scan` holds a band of a grid's rows, the
  // first of them grid row `first_row` (row_band.hpp), whose elevations
  // the rows get: the whole grid's directions, bit for bit.
  explicit GridDirections(const Scan& scan, int first_row = 0);

  // (An empty per-pixel grid counts as spherical: it has no pixel to ask about.)
  bool is_per_pixel() const { return !per_pixel.empty(); }

  // Direction of pixel (row, col); the zero vector where a per-pixel grid
  // has none. Asserts that row and column lie in the grid.
  Eigen::Vector3f at(int row, int col) const {
    assert(row >= 0 && col >= 0 && col < columns && "pixel inside the grid");
    if (is_per_pixel()) {
      const std::size_t i = static_cast<std::size_t>(row) * columns + col;
      assert(i < per_pixel.size() && "pixel inside the grid");
      return per_pixel[i];
    }
    assert(static_cast<std::size_t>(row) < cos_el.size() && "pixel inside the grid");
    return {cos_el[row] * cos_az[col], cos_el[row] * sin_az[col], sin_el[row]};
  }
};

// A normal estimate and the share of its window it used.
struct NormalFit {
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, towards the scanner, when ok
  float cos_incidence = 0.0f;                        // |normal · viewing direction|
  int used = 0;                                      // pixels that took part
  int window = 1;                                    // pixels of the whole window
  bool ok = false;                                   // a surface normal was found
};

// Covariance fit over the (2·edge_window_radius + 1)² window around
// (row, col) of the masked pixels whose log-range differs from the centre's
// by at most depth_jump_relative per pixel of (Chebyshev) distance; ok is
// false with fewer than 3 such pixels or when they form a line or a blob
// (second eigenvalue ≤ 4 × the first). `range_m`, `mask` and `log_range` are
// rows × columns arrays of the scan, log_range NaN where mask is 0; the
// centre must be masked.
NormalFit covariance_fit(const GridDirections& directions, const float* range_m,
                         const std::uint8_t* mask, const float* log_range, int row, int col,
                         int rows, const GeometrySettings& settings);

// Fallback pixels come in runs along edges: covariance_fits fits this many
// horizontally adjacent pixels at once, their windows read as consecutive
// pixels of each row, several times faster per pixel.
inline constexpr int kCovarianceLanes = 4;

// Whether covariance_fits can take pixels (row, col … col + kCovarianceLanes
// − 1): a spherical grid and all their windows inside it.
bool covariance_lanes_fit(const GridDirections& directions, int row, int col, int rows,
                          const GeometrySettings& settings);

// covariance_fit of pixels (row, col + j) for the lanes j < kCovarianceLanes
// whose bit is set in `wanted`, into fits[j] (other entries untouched); the
// same results as covariance_fit, bit for bit (the mask is read through
// log_range's NaN). Asserts covariance_lanes_fit.
void covariance_fits(const GridDirections& directions, const float* range_m, const float* log_range,
                     int row, int col, int rows, const GeometrySettings& settings, unsigned wanted,
                     NormalFit* fits);

}  // namespace scanbench::acquisition

// What region growing compares, prepared once per scan (seed 004 §4.1): the
// scan's grid with, per pixel, its point, normal, perceptual colour and
// intensity, and whether it may belong to a region at all. A click then
// only reads these arrays, so its cost grows with the region, not the scan.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::segmentation {

// The channel a region grows on.
enum class Channel : std::uint8_t { kRange, kColor, kIntensity, kNormal };

// "range", "color", "intensity", "normal".
std::string_view channel_name(Channel channel);
// The channel called `name`, or none.
std::optional<Channel> channel_from_name(std::string_view name);

// The shape of a scan's grid and how its pixels neighbour each other: the
// 8-neighbourhood, with column 0 next to the last column when the panorama
// closes the full circle (acquisition::wraps_around). Rows never wrap.
struct GridShape {
  int rows = 0;
  int columns = 0;
  bool wraps = false;

  std::size_t pixel_count() const { return static_cast<std::size_t>(rows) * columns; }
  std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * columns + col;
  }
  // Column `col` brought into [0, columns) on a wrapping grid; none when it
  // lies outside a grid that does not wrap.
  std::optional<int> column(long long col) const;

  // Calls visit(row, col) for each of the (up to 8) neighbours of (row, col).
  template <typename Visit>
  void for_each_neighbour(int row, int col, Visit&& visit) const {
    for (int dr = -1; dr <= 1; ++dr) {
      const int r = row + dr;
      if (r < 0 || r >= rows) continue;
      for (int dc = -1; dc <= 1; ++dc) {
        if (dr == 0 && dc == 0) continue;
        int c = col + dc;
        if (c < 0 || c >= columns) {
          if (!wraps) continue;
          c = c < 0 ? columns - 1 : 0;
        }
        visit(r, c);
      }
    }
  }
};

GridShape grid_shape(const acquisition::Scan& scan);

// Per pixel, row-major like the scan. Arrays of channels the scan lacks are
// empty.
struct SegmentationGrid {
  GridShape shape;
  // 1 where the pixel may join a region: a return that is not a mixed pixel
  // (acquisition::in_model).
  std::vector<std::uint8_t> usable;
  std::vector<Eigen::Vector3f> point;  // scan frame [m]; meaningless where !usable
  // Unit normal, scan frame; the zero vector where the geometry has none.
  std::vector<Eigen::Vector3f> normal;
  // The point's footprint radius [m] (acquisition::ScanGeometry): about half
  // the gap to its neighbours. The unit of the continuity tolerances.
  std::vector<float> footprint_m;
  std::vector<std::array<float, 3>> lab;  // CIE L*a*b* (D65) of the colour
  std::vector<float> intensity;
  // The spread of the scan's intensities (2nd to 98th percentile of the
  // usable pixels): the unit of the intensity channel's tolerance. 1 when
  // the scan has no intensity or all are equal.
  float intensity_spread = 1.0f;
  // The range noise σ(range) of the scanner, for the continuity test.
  acquisition::RangeNoise range_noise;
};

struct GridSettings {
  acquisition::RangeNoise range_noise;  // the scan's (ScanGeometry::range_noise, or a model given)
  int threads = 0;                      // 0 = all cores; results do not depend on it
};

// Prepares `scan` with its `geometry` (same size, asserted; at most 2^32 − 1
// pixels, asserted: pixel indices are 32-bit).
SegmentationGrid prepare_grid(const acquisition::Scan& scan,
                              const acquisition::ScanGeometry& geometry,
                              const GridSettings& settings);

// CIE L*a*b* (D65 white) of an 8-bit sRGB colour.
std::array<float, 3> srgb_to_lab(std::uint8_t r, std::uint8_t g, std::uint8_t b);

}  // namespace scanbench::segmentation

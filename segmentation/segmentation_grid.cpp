#include "segmentation/segmentation_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "acquisition/color_space.hpp"
#include "core/parallel.hpp"

namespace scanbench::segmentation {

namespace {

constexpr std::array<std::string_view, 4> kChannelNames = {"range", "color", "intensity", "normal"};

float intensity_spread(const acquisition::Scan& scan, const std::vector<std::uint8_t>& usable) {
  const auto [low, high] = acquisition::intensity_range(scan, usable);
  return high > low ? high - low : 1.0f;
}

}  // namespace

std::string_view channel_name(Channel channel) {
  return kChannelNames[static_cast<std::size_t>(channel)];
}

std::optional<Channel> channel_from_name(std::string_view name) {
  for (std::size_t k = 0; k < kChannelNames.size(); ++k) {
    if (kChannelNames[k] == name) return static_cast<Channel>(k);
  }
  return std::nullopt;
}

std::optional<int> GridShape::column(long long col) const {
  if (col >= 0 && col < columns) return static_cast<int>(col);
  if (!wraps) return std::nullopt;
  const long long wrapped = col % columns;
  return static_cast<int>(wrapped < 0 ? wrapped + columns : wrapped);
}

GridShape grid_shape(const acquisition::Scan& scan) {
  return {scan.rows, scan.columns, acquisition::wraps_around(scan)};
}

std::array<float, 3> srgb_to_lab(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  const Eigen::Vector3d lab = acquisition::srgb_to_lab({r, g, b});
  return {static_cast<float>(lab.x()), static_cast<float>(lab.y()), static_cast<float>(lab.z())};
}

SegmentationGrid prepare_grid(const acquisition::Scan& scan,
                              const acquisition::ScanGeometry& geometry,
                              const GridSettings& settings) {
  const std::size_t n = scan.pixel_count();
  assert(geometry.normal.size() == n && geometry.footprint_m.size() == n &&
         "geometry of another scan");
  assert(n <= std::numeric_limits<std::uint32_t>::max() && "pixel indices are 32-bit");
  SegmentationGrid grid;
  grid.shape = grid_shape(scan);
  grid.range_noise = settings.range_noise;
  grid.usable.resize(n);
  grid.point.resize(n);
  grid.normal = geometry.normal;
  grid.footprint_m = geometry.footprint_m;
  if (scan.has_color()) grid.lab.resize(n);
  if (scan.has_intensity()) grid.intensity = scan.intensity;
  core::parallel_for_index(scan.rows, settings.threads, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      grid.usable[i] = acquisition::in_model(scan, geometry, i) ? 1 : 0;
      grid.point[i] = acquisition::point_in_scan(scan, row, col);
      if (!grid.lab.empty()) {
        grid.lab[i] = srgb_to_lab(scan.rgb[3 * i], scan.rgb[3 * i + 1], scan.rgb[3 * i + 2]);
      }
    }
  });
  if (scan.has_intensity()) grid.intensity_spread = intensity_spread(scan, grid.usable);
  return grid;
}

}  // namespace scanbench::segmentation

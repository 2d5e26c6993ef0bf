#include "segmentation/segmentation_grid.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "core/parallel.hpp"

namespace scanbench::segmentation {

namespace {

constexpr std::array<std::string_view, 4> kChannelNames = {"range", "color", "intensity", "normal"};

// sRGB decoding (IEC 61966-2-1) of every 8-bit value.
std::array<float, 256> make_linear_table() {
  std::array<float, 256> table{};
  for (int v = 0; v < 256; ++v) {
    const double c = v / 255.0;
    table[v] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
  }
  return table;
}

// CIE 1976 L*a*b* companding of a tristimulus ratio.
float lab_f(float t) {
  constexpr float kDelta = 6.0f / 29.0f;
  return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3.0f * kDelta * kDelta) + 4.0f / 29.0f;
}

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
  static const std::array<float, 256> linear = make_linear_table();
  const float R = linear[r], G = linear[g], B = linear[b];
  // Linear sRGB to XYZ, divided by the D65 white point.
  const float x = (0.4124f * R + 0.3576f * G + 0.1805f * B) / 0.95047f;
  const float y = 0.2126f * R + 0.7152f * G + 0.0722f * B;
  const float z = (0.0193f * R + 0.1192f * G + 0.9505f * B) / 1.08883f;
  const float fx = lab_f(x), fy = lab_f(y), fz = lab_f(z);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
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

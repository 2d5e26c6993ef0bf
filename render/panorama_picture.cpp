#include "render/panorama_picture.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "modeling/store/layer_store.hpp"
#include "render/object_palette.hpp"

namespace scanbench::render {

namespace {

std::uint8_t blend(std::uint8_t a, std::uint8_t b, float t) {
  return static_cast<std::uint8_t>(
      std::lround((1.0f - t) * static_cast<float>(a) + t * static_cast<float>(b)));
}

// The 2nd and 98th percentiles of the valid ranges [m].
std::array<float, 2> range_span(const acquisition::Scan& scan) {
  std::vector<float> ranges;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i)
    if (scan.valid[i]) ranges.push_back(scan.range_m[i]);
  if (ranges.empty()) return {0.0f, 1.0f};
  std::sort(ranges.begin(), ranges.end());
  const float low = ranges[ranges.size() / 50];
  return {low, std::max(ranges[ranges.size() - 1 - ranges.size() / 50], low + 1e-3f)};
}

// Pixel `i` of a valid return, in `channel`.
void channel_of(const acquisition::Scan& scan, const PanoramaOverlays& overlays,
                PanoramaChannel channel, std::array<float, 2> span, std::size_t i,
                std::uint8_t* p) {
  switch (channel) {
    case PanoramaChannel::kColor:
      if (scan.has_color()) {
        for (int c = 0; c < 3; ++c) p[c] = scan.rgb[3 * i + static_cast<std::size_t>(c)];
        break;
      }
      [[fallthrough]];
    case PanoramaChannel::kIntensity: {
      const float v = scan.has_intensity() ? std::clamp(scan.intensity[i], 0.0f, 1.0f) : 0.5f;
      p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(255.0f * v));
      break;
    }
    case PanoramaChannel::kRange: {
      const float t = std::clamp((scan.range_m[i] - span[0]) / (span[1] - span[0]), 0.0f, 1.0f);
      p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(255.0f * (1.0f - t)));
      break;
    }
    case PanoramaChannel::kNormal: {
      const Eigen::Vector3f normal =
          overlays.normals.empty() ? Eigen::Vector3f::Zero() : overlays.normals[i];
      for (int c = 0; c < 3; ++c)
        p[c] = static_cast<std::uint8_t>(std::lround(127.5f + 127.5f * normal[c]));
      break;
    }
  }
}

}  // namespace

Picture panorama_picture(const acquisition::Scan& scan, const PanoramaOverlays& overlays,
                         PanoramaChannel channel) {
  const std::size_t n = scan.pixel_count();
  assert((overlays.normals.empty() || overlays.normals.size() == n) &&
         (overlays.membership.empty() || overlays.membership.size() == n) &&
         (overlays.selection.empty() || overlays.selection.size() == n) &&
         "overlays are empty or one element per pixel");
  Picture out{scan.columns, scan.rows, std::vector<std::uint8_t>(4 * n, 0)};
  const std::array<float, 2> span =
      channel == PanoramaChannel::kRange ? range_span(scan) : std::array<float, 2>{0.0f, 1.0f};
  constexpr std::array<std::uint8_t, 3> kYellow = {255, 230, 40};
  constexpr std::array<std::uint8_t, 3> kCyan = {40, 230, 255};
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* p = &out.rgba[4 * i];
    p[3] = 255;
    if (!scan.valid[i]) {
      p[0] = p[1] = p[2] = 24;
      continue;
    }
    channel_of(scan, overlays, channel, span, i, p);
    const std::uint32_t owner = overlays.membership.empty() ? 0 : overlays.membership[i];
    if (owner != 0 && owner == overlays.highlight) {
      for (std::size_t c = 0; c < 3; ++c) p[c] = blend(p[c], kCyan[c], 0.7f);
    } else if (owner != 0 && owner != store::kDeletedPoints) {
      const std::array<std::uint8_t, 3> tint = object_color(owner);
      for (std::size_t c = 0; c < 3; ++c) p[c] = blend(p[c], tint[c], 0.45f);
    }
    if (!overlays.selection.empty() && overlays.selection[i] != 0) {
      for (std::size_t c = 0; c < 3; ++c) p[c] = blend(p[c], kYellow[c], 0.6f);
    }
  }
  return out;
}

}  // namespace scanbench::render

#include "acquisition/panorama_projection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace scanbench::acquisition {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kFarM = 500.0;  // local_origin.hpp's max_per_pixel_range_m
constexpr int kGapBins = 3600;   // azimuth histogram for the widest gap

Eigen::Vector3d projection_centre(std::span<const Eigen::Vector3d> points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double farthest = 0.0;
  for (const Eigen::Vector3d& p : points) {
    sum += p;
    farthest = std::max(farthest, p.norm());
  }
  if (farthest <= kFarM || points.empty()) return Eigen::Vector3d::Zero();
  return (sum / static_cast<double>(points.size())).array().round().matrix();
}

// The azimuth just after the widest run of empty histogram bins, so that
// every point's azimuth measured from it lies in [0, 2π).
double azimuth_start(const std::vector<double>& azimuths) {
  std::vector<std::uint8_t> occupied(kGapBins, 0);
  for (const double a : azimuths) {
    const int bin = static_cast<int>((a + std::numbers::pi) / kTwoPi * kGapBins);
    occupied[std::clamp(bin, 0, kGapBins - 1)] = 1;
  }
  int best_end = 0, best_length = 0;
  for (int start = 0; start < kGapBins; ++start) {
    if (occupied[start] || occupied[(start + kGapBins - 1) % kGapBins] == 0) continue;
    int length = 0;
    while (length < kGapBins && !occupied[(start + length) % kGapBins]) ++length;
    if (length > best_length) best_length = length, best_end = (start + length) % kGapBins;
  }
  return -std::numbers::pi + kTwoPi * best_end / kGapBins;
}

}  // namespace

PanoramaProjection project_to_panorama(std::span<const Eigen::Vector3d> points) {
  PanoramaProjection out;
  out.pixel.assign(points.size(), -1);
  if (points.empty()) return out;
  const Eigen::Vector3d centre = projection_centre(points);
  std::vector<double> azimuth(points.size()), elevation(points.size()), range(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d d = points[i] - centre;
    range[i] = d.norm();
    azimuth[i] = std::atan2(d.y(), d.x());
    elevation[i] = std::asin(std::clamp(d.z() / std::max(range[i], 1e-300), -1.0, 1.0));
  }
  const double start = azimuth_start(azimuth);
  double az_extent = 0.0, el_min = HUGE_VAL, el_max = -HUGE_VAL;
  for (std::size_t i = 0; i < points.size(); ++i) {
    azimuth[i] = std::fmod(azimuth[i] - start + 2.0 * kTwoPi, kTwoPi);
    az_extent = std::max(az_extent, azimuth[i]);
    el_min = std::min(el_min, elevation[i]);
    el_max = std::max(el_max, elevation[i]);
  }
  // The covered area on a coarse grid (about 16 points per cell), then the
  // step at which the points would fill it once each.
  const auto n = static_cast<double>(points.size());
  const double box = std::max(az_extent, 1e-6) * std::max(el_max - el_min, 1e-6);
  const double coarse = std::sqrt(box * 16.0 / n);
  const int coarse_columns = static_cast<int>(az_extent / coarse) + 1;
  const int coarse_rows = static_cast<int>((el_max - el_min) / coarse) + 1;
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(coarse_columns) * coarse_rows, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    occupied[static_cast<std::size_t>((el_max - elevation[i]) / coarse) * coarse_columns +
             static_cast<std::size_t>(azimuth[i] / coarse)] = 1;
  }
  const auto cells = static_cast<double>(std::count(occupied.begin(), occupied.end(), 1));
  double step = std::sqrt(cells * coarse * coarse / n);
  // At most 4 pixels per point (and 2^30 in all).
  const double min_step = std::sqrt(box / (4.0 * n));
  step = std::max({step, min_step, 1e-7});
  out.step_rad = step;
  out.columns = static_cast<int>(std::llround(az_extent / step)) + 1;
  out.rows = static_cast<int>(std::llround((el_max - el_min) / step)) + 1;
  // Nearest point first: it is the one a scanner would have seen.
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return range[a] < range[b]; });
  std::vector<std::uint8_t> taken(static_cast<std::size_t>(out.rows) * out.columns, 0);
  for (const std::size_t i : order) {
    const auto row =
        std::min<std::int64_t>(std::llround((el_max - elevation[i]) / step), out.rows - 1);
    const auto col = std::min<std::int64_t>(std::llround(azimuth[i] / step), out.columns - 1);
    const std::int64_t p = row * out.columns + col;
    if (taken[p]) {
      ++out.collisions;
      continue;
    }
    taken[p] = 1;
    out.pixel[i] = p;
  }
  return out;
}

}  // namespace scanbench::acquisition

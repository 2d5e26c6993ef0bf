#include "acquisition/formats/panorama_projection.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace scanbench::acquisition {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kFarM = 500.0;              // local_origin.hpp's max_per_pixel_range_m
constexpr int kGapBins = 3600;               // azimuth histogram for the widest gap
constexpr double kMaxPixels = 1073741824.0;  // 2^30

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

// The median distance in the (azimuth, elevation) plane from a sample of
// at most 2^14 points to their nearest other point: the step of a scan
// sampled on a regular grid, and about half the mean spacing of scattered
// points. The points are bucketed by counting sort into cells of about 16
// points each, and each sample searches its 3 × 3 cells. 0 when no sample
// has a neighbour there.
double median_neighbour_spacing(const std::vector<double>& azimuth,
                                const std::vector<double>& elevation, double el_max,
                                double az_extent, double box) {
  const std::size_t n = azimuth.size();
  const double cell = std::sqrt(box * 16.0 / static_cast<double>(n));
  const auto columns = static_cast<std::size_t>(az_extent / cell) + 1;
  const auto rows = static_cast<std::size_t>(
                        (el_max - *std::min_element(elevation.begin(), elevation.end())) / cell) +
                    1;
  const auto cell_of = [&](std::size_t i, std::size_t& row, std::size_t& col) {
    row = std::min(rows - 1, static_cast<std::size_t>((el_max - elevation[i]) / cell));
    col = std::min(columns - 1, static_cast<std::size_t>(azimuth[i] / cell));
  };
  std::vector<std::size_t> first(rows * columns + 1, 0), members(n);
  for (std::size_t i = 0, r, c; i < n; ++i) cell_of(i, r, c), ++first[r * columns + c + 1];
  for (std::size_t k = 1; k < first.size(); ++k) first[k] += first[k - 1];
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  for (std::size_t i = 0, r, c; i < n; ++i) cell_of(i, r, c), members[fill[r * columns + c]++] = i;
  std::vector<double> spacing;
  const std::size_t stride = std::max<std::size_t>(1, n >> 14);
  for (std::size_t i = 0; i < n; i += stride) {
    std::size_t row, col;
    cell_of(i, row, col);
    double best = HUGE_VAL;
    for (std::size_t r = row > 0 ? row - 1 : 0; r <= std::min(rows - 1, row + 1); ++r) {
      for (std::size_t c = col > 0 ? col - 1 : 0; c <= std::min(columns - 1, col + 1); ++c) {
        for (std::size_t k = first[r * columns + c]; k < first[r * columns + c + 1]; ++k) {
          const double da = azimuth[members[k]] - azimuth[i];
          const double de = elevation[members[k]] - elevation[i];
          const double d2 = da * da + de * de;
          if (d2 > 1e-18 && d2 < best) best = d2;  // not itself, nor a point behind it
        }
      }
    }
    if (best < HUGE_VAL) spacing.push_back(std::sqrt(best));
  }
  if (spacing.empty()) return 0.0;
  const auto middle = spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2);
  std::nth_element(spacing.begin(), middle, spacing.end());
  return *middle;
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
  const auto n = static_cast<double>(points.size());
  const double box = std::max(az_extent, 1e-6) * std::max(el_max - el_min, 1e-6);
  double step = median_neighbour_spacing(azimuth, elevation, el_max, az_extent, box);
  // At most 4 pixels per point (and 2^30 in all).
  // Steps of at least 10^-7 rad whose grid is within 4 pixels per point and
  // 2^30 pixels (each side of the box gains at most one pixel in rounding).
  // A step of at least the longer side over 2n keeps a grid of points on a
  // line (whose box is thin) within 2n + 1 pixels.
  const double min_step = std::max(std::sqrt(box / std::min(4.0 * n, 0.9 * kMaxPixels)),
                                   std::max(az_extent, el_max - el_min) / (2.0 * n));
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
        std::clamp<std::int64_t>(std::llround((el_max - elevation[i]) / step), 0, out.rows - 1);
    const auto col = std::clamp<std::int64_t>(std::llround(azimuth[i] / step), 0, out.columns - 1);
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

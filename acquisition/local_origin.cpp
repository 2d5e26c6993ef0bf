#include "acquisition/local_origin.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <vector>

namespace scanbench::acquisition {
namespace {

// Points closer than this [m] to a per-pixel origin would have no direction.
constexpr double kMinRangeM = 1e-3;

std::vector<Eigen::Vector3d> relative_to(std::span<const Eigen::Vector3d> points,
                                         const std::vector<std::uint8_t>& valid,
                                         const Eigen::Vector3d& origin) {
  std::vector<Eigen::Vector3d> out(points.size(), Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (valid[i]) out[i] = points[i] - origin;
  }
  return out;
}

// Where the valid points lie, from one pass: how far from the file's origin,
// and their centroid.
struct Spread {
  double farthest_m = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

Spread spread_of(std::span<const Eigen::Vector3d> points, const std::vector<std::uint8_t>& valid) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double farthest_sq = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!valid[i]) continue;
    sum += points[i];
    farthest_sq = std::max(farthest_sq, points[i].squaredNorm());
    ++count;
  }
  if (count == 0) return {};
  return {std::sqrt(farthest_sq), sum / static_cast<double>(count)};
}

struct RangeSpan {
  double nearest_m = std::numeric_limits<double>::infinity(), farthest_m = 0.0;
};

// Ranges (and, for per-pixel grids, directions) of the points measured from
// `origin`, in one pass; returns the valid points' least and largest range.
RangeSpan set_ranges(Scan& scan, std::span<const Eigen::Vector3d> points,
                     const Eigen::Vector3d& origin, bool directions) {
  RangeSpan span;
  scan.range_m.resize(points.size());  // every entry is written below
  // A scattered scan's directions are rewritten in place (every entry).
  std::vector<Eigen::Vector3f> unit;
  if (auto* grid = std::get_if<PerPixelDirections>(&scan.angles); directions && grid != nullptr)
    unit = std::move(grid->directions);
  if (directions) unit.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i] - origin;
    const double range = scan.valid[i] ? p.norm() : 0.0;
    span.farthest_m = std::max(span.farthest_m, range);
    if (scan.valid[i]) span.nearest_m = std::min(span.nearest_m, range);
    scan.range_m[i] = static_cast<float>(range);
    if (directions) {
      unit[i] =
          scan.valid[i] ? Eigen::Vector3f((p / range).cast<float>()) : Eigen::Vector3f::Zero();
    }
  }
  if (directions) scan.angles = PerPixelDirections{std::move(unit), scan.is_scattered()};
  return span;
}

// The largest distance [m] between a valid point of `points` and where the
// scan puts it: origin + its double direction × its float range.
double largest_round_trip_error(const Scan& scan, std::span<const Eigen::Vector3d> points,
                                const Eigen::Vector3d& origin) {
  double largest = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!scan.valid[i]) continue;
    const int row = static_cast<int>(i / static_cast<std::size_t>(scan.columns));
    const int col = static_cast<int>(i % static_cast<std::size_t>(scan.columns));
    const Eigen::Vector3d back =
        origin + direction_precise(scan, row, col) * static_cast<double>(scan.range_m[i]);
    largest = std::max(largest, (back - points[i]).squaredNorm());
  }
  return std::sqrt(largest);
}

// Ranges from `origin` and, unless the scan's angles are a panorama whose
// fit moved points by `panorama_deviation_m`, per-pixel directions; then
// the round trip of every point bounded, or checked where the bound does
// not settle it. A float range errs by 6e-8 of itself, a float unit
// direction by 1e-7 of the range. Per-pixel directions fail unchecked
// (max_error_m infinite) when a point lies within kMinRangeM of the origin:
// it has no direction.
LocalOriginResult place(Scan& scan, std::span<const Eigen::Vector3d> points,
                        const Eigen::Vector3d& origin, std::optional<double> panorama_deviation_m,
                        const LocalOriginSettings& settings) {
  const bool spherical = panorama_deviation_m.has_value();
  LocalOriginResult result{origin, spherical};
  const RangeSpan span = set_ranges(scan, points, origin, !spherical);
  result.farthest_m = span.farthest_m;
  const double bound =
      spherical ? *panorama_deviation_m + 6e-8 * span.farthest_m : 1.6e-7 * span.farthest_m;
  if (!spherical && span.nearest_m < kMinRangeM) {
    result.max_error_m = std::numeric_limits<double>::infinity();
  } else {
    result.max_error_m =
        bound <= settings.max_error_m ? bound : largest_round_trip_error(scan, points, origin);
  }
  return result;
}

}  // namespace

LocalOriginResult set_grid_from_points(Scan& scan, std::span<const Eigen::Vector3d> points_file,
                                       const std::optional<Eigen::Vector3d>& centre_hint_file,
                                       const LocalOriginSettings& settings) {
  assert(points_file.size() == scan.pixel_count() && scan.valid.size() == scan.pixel_count() &&
         "one point and one validity flag per pixel");
  std::vector<Eigen::Vector3d> candidates{Eigen::Vector3d::Zero()};
  if (centre_hint_file && centre_hint_file->allFinite() && !centre_hint_file->isZero(0.0)) {
    candidates.push_back(*centre_hint_file);
  }
  if (!settings.try_spherical || scan.is_scattered()) candidates.clear();
  // The first representation whose every point comes back within
  // max_error_m: a panorama around a candidate centre, then per-pixel
  // directions from the file's origin (points near it), then from the
  // points' centroid. Float ranges of points far from a centre the fit
  // accepted (a scanner position kilometres away) fail the first.
  std::optional<LocalOriginResult> result;
  for (const Eigen::Vector3d& centre : candidates) {
    const SphericalFitResult fit =
        centre.isZero(0.0) ? fit_spherical_angles(scan.rows, scan.columns, points_file, scan.valid,
                                                  settings.angle_fit)
                           : fit_spherical_angles(scan.rows, scan.columns,
                                                  relative_to(points_file, scan.valid, centre),
                                                  scan.valid, settings.angle_fit);
    if (!fit.regular) continue;
    scan.angles = fit.angles;
    result = place(scan, points_file, centre, fit.max_deviation_m, settings);
    if (result->max_error_m <= settings.max_error_m) break;
    result.reset();
  }
  const Spread spread = result ? Spread{} : spread_of(points_file, scan.valid);
  if (!result && spread.farthest_m <= settings.max_per_pixel_range_m) {
    result = place(scan, points_file, Eigen::Vector3d::Zero(), std::nullopt, settings);
    if (result->max_error_m > settings.max_error_m) result.reset();
  }
  // The centroid rounded to whole metres, moved by a metre in z (or to the
  // next double, where a metre is below its precision) while a point sits
  // on it.
  for (Eigen::Vector3d origin = spread.centroid.array().round().matrix(); !result;
       origin.z() = std::max(origin.z() + 1.0, std::nextafter(origin.z(), HUGE_VAL))) {
    result = place(scan, points_file, origin, std::nullopt, settings);
    if (!std::isfinite(result->max_error_m)) result.reset();
  }
  scan.T_world_scan = scan.T_world_scan * Eigen::Translation3d(result->origin_file);
  scan.import_round_trip_m = result->max_error_m;
  return *result;
}

LocalOriginResult set_scattered_points(Scan& scan, std::vector<Eigen::Vector3d> points_file) {
  assert(scan.is_scattered() && points_file.size() == count_valid(scan) &&
         "one point per valid pixel of a scattered scan");
  points_file.resize(scan.pixel_count(), Eigen::Vector3d::Zero());  // the last row's padding
  return set_grid_from_points(scan, points_file, std::nullopt);
}

}  // namespace scanbench::acquisition

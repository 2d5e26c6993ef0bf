#include "acquisition/scan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "core/memory.hpp"

namespace scanbench::acquisition {

Scan make_empty_scan(int rows, int columns, bool with_intensity, bool with_color) {
  assert(rows >= 0 && columns >= 0 && "scan dimensions must be non-negative");
  Scan scan;
  scan.rows = rows;
  scan.columns = columns;
  const std::size_t n = scan.pixel_count();
  core::assign_mapped(scan.range_m, n, 0.0f);
  core::assign_mapped(scan.valid, n, std::uint8_t{0});
  if (with_intensity) core::assign_mapped(scan.intensity, n, 0.0f);
  if (with_color) core::assign_mapped(scan.rgb, 3 * n, std::uint8_t{0});
  return scan;
}

namespace {

// A grid about as wide as tall.
std::pair<std::size_t, std::size_t> scattered_grid(std::size_t points) {
  const auto columns = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(points))));
  return {columns == 0 ? 0 : (points + columns - 1) / columns, columns};
}

}  // namespace

std::size_t scattered_pixel_count(std::size_t points) {
  const auto [rows, columns] = scattered_grid(points);
  return rows * columns;
}

Scan without_arrays(const Scan& scan) {
  Scan out;
  out.name = scan.name;
  out.rows = scan.rows;
  out.columns = scan.columns;
  if (const auto* per_pixel = std::get_if<PerPixelDirections>(&scan.angles)) {
    out.angles = PerPixelDirections{{}, per_pixel->scattered};
  } else {
    out.angles = scan.angles;
  }
  out.T_world_scan = scan.T_world_scan;
  out.scanner = scan.scanner;
  out.import_round_trip_m = scan.import_round_trip_m;
  return out;
}

Scan make_scattered_scan(std::size_t points, bool with_intensity, bool with_color) {
  const auto [rows, columns] = scattered_grid(points);
  assert(rows < (1u << 31) && columns < (1u << 31) && "a scattered scan of at most 2^62 points");
  Scan scan = make_empty_scan(static_cast<int>(rows), static_cast<int>(columns), with_intensity,
                              with_color);
  std::fill_n(scan.valid.begin(), points, std::uint8_t{1});
  std::vector<Eigen::Vector3f> directions;
  core::assign_mapped(directions, scan.pixel_count(), Eigen::Vector3f::Zero().eval());
  scan.angles = PerPixelDirections{std::move(directions), true};
  return scan;
}

Eigen::Vector3d direction_precise(const Scan& scan, int row, int col, int first_row) {
  assert(row >= 0 && row < scan.rows && col >= 0 && col < scan.columns && first_row >= 0);
  if (const auto* spherical = std::get_if<SphericalAngles>(&scan.angles)) {
    const double az = spherical->azimuth(col);
    const double el = spherical->elevation(first_row + row);
    const double cos_el = std::cos(el);
    return {cos_el * std::cos(az), cos_el * std::sin(az), std::sin(el)};
  }
  const Eigen::Vector3d d =
      std::get<PerPixelDirections>(scan.angles).directions[scan.index(row, col)].cast<double>();
  const double norm = d.norm();
  return norm > 0.0 ? Eigen::Vector3d(d / norm) : Eigen::Vector3d::Zero();
}

SphericalDirections::SphericalDirections(const Scan& scan) {
  const auto& model = std::get<SphericalAngles>(scan.angles);
  rows_.reserve(static_cast<std::size_t>(scan.rows));
  for (int row = 0; row < scan.rows; ++row) {
    const double el = model.elevation(row);
    rows_.emplace_back(std::cos(el), std::sin(el));
  }
  columns_.reserve(static_cast<std::size_t>(scan.columns));
  for (int col = 0; col < scan.columns; ++col) {
    const double az = model.azimuth(col);
    columns_.emplace_back(std::cos(az), std::sin(az));
  }
}

Eigen::Vector3f direction(const Scan& scan, int row, int col) {
  if (scan.is_spherical()) return direction_precise(scan, row, col).cast<float>();
  return std::get<PerPixelDirections>(scan.angles).directions[scan.index(row, col)];
}

Eigen::Vector3f point_in_scan(const Scan& scan, int row, int col) {
  return scan.range_m[scan.index(row, col)] * direction(scan, row, col);
}

Eigen::Vector3d point_in_world(const Scan& scan, int row, int col, int first_row) {
  const double range = scan.range_m[scan.index(row, col)];
  return scan.T_world_scan * (range * direction_precise(scan, row, col, first_row));
}

bool wraps_around(const Scan& scan) {
  const auto* model = std::get_if<SphericalAngles>(&scan.angles);
  if (model == nullptr || scan.columns < 3) return false;
  const double step = std::abs(model->azimuth_step_rad);
  return std::abs(step * scan.columns - 2.0 * std::numbers::pi) <= 0.5 * step;
}

std::size_t count_valid(const Scan& scan) {
  std::size_t count = 0;
  for (const std::uint8_t v : scan.valid) count += v != 0;
  return count;
}

std::pair<float, float> intensity_range(const Scan& scan, const std::vector<std::uint8_t>& usable) {
  assert(!scan.has_intensity() || usable.size() == scan.pixel_count());
  std::vector<float> values;
  values.reserve(scan.intensity.size());
  for (std::size_t i = 0; i < scan.intensity.size(); ++i) {
    if (usable[i] && std::isfinite(scan.intensity[i])) values.push_back(scan.intensity[i]);
  }
  if (values.size() < 2) return {0.0f, 1.0f};
  const auto at = [&values](double share) {
    const auto k = static_cast<std::ptrdiff_t>(share * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    return values[static_cast<std::size_t>(k)];
  };
  const float low = at(0.02);
  return {low, at(0.98)};
}

std::optional<Eigen::AlignedBox3d> world_bounds(const Scan& scan) {
  return world_bounds(scan, scan.T_world_scan);
}

std::optional<Eigen::AlignedBox3d> world_bounds(const Scan& scan,
                                                const Eigen::Isometry3d& T_world_scan) {
  Eigen::AlignedBox3d box;  // starts empty
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      const double range = scan.range_m[i];
      box.extend(T_world_scan * (range * direction_precise(scan, row, col)));
    }
  }
  if (box.isEmpty()) return std::nullopt;
  return box;
}

std::string check_consistency(const Scan& scan) {
  if (scan.rows < 0 || scan.columns < 0) return "negative dimensions";
  const std::size_t n = scan.pixel_count();
  if (scan.range_m.size() != n) return "range channel size differs from rows x columns";
  if (scan.valid.size() != n) return "validity mask size differs from rows x columns";
  if (!scan.intensity.empty() && scan.intensity.size() != n) {
    return "intensity channel size differs from rows x columns";
  }
  if (!scan.rgb.empty() && scan.rgb.size() != 3 * n) {
    return "rgb channel size differs from 3 x rows x columns";
  }
  if (const auto* per_pixel = std::get_if<PerPixelDirections>(&scan.angles)) {
    if (per_pixel->directions.size() != n) return "direction count differs from rows x columns";
    if (per_pixel->scattered) {
      const auto first_empty = std::find(scan.valid.begin(), scan.valid.end(), 0);
      if (std::find(first_empty, scan.valid.end(), 1) != scan.valid.end()) {
        return "a scattered scan's points do not fill its first pixels";
      }
    }
  }
  return {};
}

}  // namespace scanbench::acquisition

#include "acquisition/spherical_fit.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <vector>

namespace scanbench::acquisition {
namespace {

double wrap_angle(double a) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  if (a >= -std::numbers::pi && a <= std::numbers::pi) return a;  // most calls: nothing to do
  return a - kTwoPi * std::round(a / kTwoPi);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Robust step along one grid axis: the median difference of the angle between
// valid neighbours along that axis (azimuths wrapped), over at most about
// 2^17 neighbour pairs spread evenly over the grid.
double median_step(std::span<const double> angle, std::span<const std::uint8_t> valid, int rows,
                   int columns, bool along_columns, bool wrap) {
  std::vector<double> steps;
  const int row_stop = along_columns ? rows : rows - 1;
  const int col_stop = along_columns ? columns - 1 : columns;
  const std::size_t pairs = static_cast<std::size_t>(std::max(row_stop, 0)) * std::max(col_stop, 0);
  const std::size_t stride =
      std::max<std::size_t>(1, pairs >> 17) | 1;  // odd: no aliasing with rows
  for (std::size_t k = 0; k < pairs; k += stride) {
    const int row = static_cast<int>(k / col_stop), col = static_cast<int>(k % col_stop);
    const std::size_t a = static_cast<std::size_t>(row) * columns + col;
    const std::size_t b = along_columns ? a + 1 : a + columns;
    if (!valid[a] || !valid[b]) continue;
    const double d = angle[b] - angle[a];
    steps.push_back(wrap ? wrap_angle(d) : d);
  }
  return median(std::move(steps));
}

// Least-squares line value = start + index · step over samples added one
// by one, in one pass: sums of the samples taken relative to the first
// (which keeps them small, so that the sums of squares lose nothing);
// keeps `step` when all samples share one index (the slope is then
// unobservable).
struct LineFit {
  bool started = false;
  double index0 = 0, value0 = 0;
  double n = 0, sum_i = 0, sum_v = 0, sum_ii = 0, sum_iv = 0;
  void add(double index, double value) {
    if (!started) started = true, index0 = index, value0 = value;
    const double i = index - index0, v = value - value0;
    n += 1;
    sum_i += i;
    sum_v += v;
    sum_ii += i * i;
    sum_iv += i * v;
  }
  void solve(double& start, double& step) const {
    const double mean_i = sum_i / n, mean_v = sum_v / n;
    const double s_ii = sum_ii - n * mean_i * mean_i;
    if (s_ii > 0) step = (sum_iv - n * mean_i * mean_v) / s_ii;
    start = value0 + mean_v - step * (index0 + mean_i);
  }
};

Eigen::Vector3d model_direction(const SphericalAngles& a, int row, int col) {
  const double az = a.azimuth(col);
  const double el = a.elevation(row);
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

// Calls visit(row, col, i) for every valid pixel, row-major.
template <typename Visit>
void for_each_valid(int rows, int columns, std::span<const std::uint8_t> valid, Visit&& visit) {
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * columns + col;
      if (valid[i]) visit(row, col, i);
    }
  }
}

// The model's start and step: robust steps first, then least-squares lines
// through the azimuths unwrapped next to the robust prediction and through
// the elevations. Asserts a valid pixel.
SphericalAngles fit_lines(std::span<const double> azimuth, std::span<const double> elevation,
                          std::span<const std::uint8_t> valid, int rows, int columns) {
  SphericalAngles angles;
  angles.azimuth_step_rad = median_step(azimuth, valid, rows, columns, true, true);
  angles.elevation_step_rad = median_step(elevation, valid, rows, columns, false, false);
  const std::size_t first = static_cast<std::size_t>(
      std::find_if(valid.begin(), valid.end(), [](std::uint8_t v) { return v != 0; }) -
      valid.begin());
  assert(first < valid.size());
  // Unwrap every azimuth next to the prediction of the robust step, then fit.
  const double reference =
      azimuth[first] - static_cast<double>(first % columns) * angles.azimuth_step_rad;
  const auto unwrapped = [&](int col, std::size_t i) {
    const double predicted = reference + col * angles.azimuth_step_rad;
    return predicted + wrap_angle(azimuth[i] - predicted);
  };
  LineFit az, el;
  for_each_valid(rows, columns, valid, [&](int row, int col, std::size_t i) {
    az.add(col, unwrapped(col, i));
    el.add(row, elevation[i]);
  });
  az.solve(angles.azimuth_start_rad, angles.azimuth_step_rad);
  el.solve(angles.elevation_start_rad, angles.elevation_step_rad);
  return angles;
}

}  // namespace

SphericalFitResult fit_spherical_angles_to_angles(int rows, int columns,
                                                  std::span<const double> azimuth,
                                                  std::span<const double> elevation,
                                                  std::span<const float> range,
                                                  std::span<const std::uint8_t> valid,
                                                  const SphericalFitSettings& settings) {
  [[maybe_unused]] const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(azimuth.size() == n && elevation.size() == n && range.size() == n && valid.size() == n);
  SphericalFitResult result;
  result.points_used = static_cast<std::size_t>(
      std::count_if(valid.begin(), valid.end(), [](std::uint8_t v) { return v != 0; }));
  if (result.points_used < 2) return result;
  const SphericalAngles& angles = result.angles =
      fit_lines(azimuth, elevation, valid, rows, columns);
  double cos_el = 1.0, model_el = 0.0, squared = 0.0;  // the largest squared deviation
  int cos_row = -1;
  for_each_valid(rows, columns, valid, [&](int row, int col, std::size_t i) {
    if (row != cos_row) {
      cos_row = row;
      model_el = angles.elevation(row);
      cos_el = std::cos(model_el);
    }
    const double d_az = cos_el * wrap_angle(azimuth[i] - angles.azimuth(col));
    const double d_el = elevation[i] - model_el;
    const double r = range[i];
    squared = std::max(squared, r * r * (d_az * d_az + d_el * d_el));
  });
  result.max_deviation_m = std::sqrt(squared);
  result.regular = result.max_deviation_m <= settings.max_deviation_m;
  return result;
}

SphericalFitResult fit_spherical_angles(int rows, int columns,
                                        std::span<const Eigen::Vector3d> points_scan,
                                        std::span<const std::uint8_t> valid,
                                        const SphericalFitSettings& settings) {
  const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(points_scan.size() == n && valid.size() == n);
  SphericalFitResult result;

  std::vector<double> azimuth(n, 0.0), elevation(n, 0.0);
  for_each_valid(rows, columns, valid, [&](int, int, std::size_t i) {
    const Eigen::Vector3d& p = points_scan[i];
    azimuth[i] = std::atan2(p.y(), p.x());
    elevation[i] = std::atan2(p.z(), std::hypot(p.x(), p.y()));
    ++result.points_used;
  });
  if (result.points_used < 2) return result;
  const SphericalAngles& angles = result.angles =
      fit_lines(azimuth, elevation, valid, rows, columns);
  for_each_valid(rows, columns, valid, [&](int row, int col, std::size_t i) {
    const double range = points_scan[i].norm();
    const double deviation = (range * model_direction(angles, row, col) - points_scan[i]).norm();
    result.max_deviation_m = std::max(result.max_deviation_m, deviation);
  });
  result.regular = result.max_deviation_m <= settings.max_deviation_m;
  return result;
}

}  // namespace scanbench::acquisition

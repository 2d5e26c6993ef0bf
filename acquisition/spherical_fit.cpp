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
  return a - kTwoPi * std::round(a / kTwoPi);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// Angles of the valid pixels, with their grid index.
struct Sample {
  int row;
  int col;
  double azimuth;
  double elevation;
};

// Robust step along one grid axis: the median difference of the angle between
// valid neighbours along that axis (azimuths wrapped).
double median_step(const std::vector<double>& angle, std::span<const std::uint8_t> valid, int rows,
                   int columns, bool along_columns, bool wrap) {
  std::vector<double> steps;
  const int row_stop = along_columns ? rows : rows - 1;
  const int col_stop = along_columns ? columns - 1 : columns;
  for (int row = 0; row < row_stop; ++row) {
    for (int col = 0; col < col_stop; ++col) {
      const std::size_t a = static_cast<std::size_t>(row) * columns + col;
      const std::size_t b = along_columns ? a + 1 : a + columns;
      if (!valid[a] || !valid[b]) continue;
      const double d = angle[b] - angle[a];
      steps.push_back(wrap ? wrap_angle(d) : d);
    }
  }
  return median(std::move(steps));
}

// Least-squares line value = start + index · step; keeps `step` when all
// samples share one index (the slope is then unobservable).
void fit_line(const std::vector<double>& index, const std::vector<double>& value, double& start,
              double& step) {
  const double n = static_cast<double>(index.size());
  double mean_i = 0, mean_v = 0;
  for (std::size_t k = 0; k < index.size(); ++k) {
    mean_i += index[k] / n;
    mean_v += value[k] / n;
  }
  double s_iv = 0, s_ii = 0;
  for (std::size_t k = 0; k < index.size(); ++k) {
    s_iv += (index[k] - mean_i) * (value[k] - mean_v);
    s_ii += (index[k] - mean_i) * (index[k] - mean_i);
  }
  if (s_ii > 0) step = s_iv / s_ii;
  start = mean_v - step * mean_i;
}

Eigen::Vector3d model_direction(const SphericalAngles& a, int row, int col) {
  const double az = a.azimuth_start_rad + col * a.azimuth_step_rad;
  const double el = a.elevation_start_rad + row * a.elevation_step_rad;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

}  // namespace

SphericalFitResult fit_spherical_angles(int rows, int columns,
                                        std::span<const Eigen::Vector3d> points_scan,
                                        std::span<const std::uint8_t> valid,
                                        const SphericalFitSettings& settings) {
  const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(points_scan.size() == n && valid.size() == n);
  SphericalFitResult result;

  std::vector<double> azimuth(n, 0.0), elevation(n, 0.0);
  std::vector<Sample> samples;
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < columns; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * columns + col;
      if (!valid[i]) continue;
      const Eigen::Vector3d& p = points_scan[i];
      azimuth[i] = std::atan2(p.y(), p.x());
      elevation[i] = std::atan2(p.z(), std::hypot(p.x(), p.y()));
      samples.push_back({row, col, azimuth[i], elevation[i]});
    }
  }
  result.points_used = samples.size();
  if (samples.size() < 2) return result;

  SphericalAngles& angles = result.angles;
  angles.azimuth_step_rad = median_step(azimuth, valid, rows, columns, true, true);
  angles.elevation_step_rad = median_step(elevation, valid, rows, columns, false, false);

  // Unwrap every azimuth next to the prediction of the robust step, then fit.
  const double reference = samples.front().azimuth - samples.front().col * angles.azimuth_step_rad;
  std::vector<double> col_index, unwrapped, row_index, elevations;
  for (const Sample& s : samples) {
    const double predicted = reference + s.col * angles.azimuth_step_rad;
    col_index.push_back(s.col);
    unwrapped.push_back(predicted + wrap_angle(s.azimuth - predicted));
    row_index.push_back(s.row);
    elevations.push_back(s.elevation);
  }
  fit_line(col_index, unwrapped, angles.azimuth_start_rad, angles.azimuth_step_rad);
  fit_line(row_index, elevations, angles.elevation_start_rad, angles.elevation_step_rad);

  for (const Sample& s : samples) {
    const std::size_t i = static_cast<std::size_t>(s.row) * columns + s.col;
    const double range = points_scan[i].norm();
    const double deviation =
        (range * model_direction(angles, s.row, s.col) - points_scan[i]).norm();
    result.max_deviation_m = std::max(result.max_deviation_m, deviation);
  }
  result.regular = result.max_deviation_m <= settings.max_deviation_m;
  return result;
}

}  // namespace scanbench::acquisition

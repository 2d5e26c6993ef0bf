// Projective data association for panoramic scans: the pixel whose beam a
// point lies on, in constant time. The scan's own angular grid is the index,
// so no kd-tree is built.
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "acquisition/scan.hpp"

namespace scanbench::registration {

class SphericalGrid {
 public:
  // Asserts that `scan` has a spherical angle model with non-zero steps.
  explicit SphericalGrid(const acquisition::Scan& scan) {
    const auto& angles = std::get<acquisition::SphericalAngles>(scan.angles);
    assert(angles.azimuth_step_rad != 0.0 && angles.elevation_step_rad != 0.0);
    rows_ = scan.rows;
    columns_ = scan.columns;
    azimuth_start_ = angles.azimuth_start_rad;
    elevation_start_ = angles.elevation_start_rad;
    inverse_azimuth_step_ = 1.0 / angles.azimuth_step_rad;
    inverse_elevation_step_ = 1.0 / angles.elevation_step_rad;
    period_columns_ = 2.0 * std::numbers::pi * std::abs(inverse_azimuth_step_);
  }

  // Row-major index of the pixel whose beam is nearest to the direction of
  // `p_scan` (a point in the scan frame [m], float or double), or -1 when the
  // direction lies outside the grid or p_scan is the origin. Panoramas that
  // close the full circle wrap around in azimuth.
  template <typename Scalar>
  std::int64_t pixel_of(const Eigen::Matrix<Scalar, 3, 1>& p_scan) const {
    const Scalar horizontal = std::hypot(p_scan.x(), p_scan.y());
    if (horizontal == Scalar(0) && p_scan.z() == Scalar(0)) return -1;
    const Scalar azimuth = std::atan2(p_scan.y(), p_scan.x());
    const Scalar elevation = std::atan2(p_scan.z(), horizontal);
    const Scalar v = static_cast<Scalar>((elevation - elevation_start_) * inverse_elevation_step_);
    const auto row = static_cast<std::int64_t>(std::floor(v + Scalar(0.5)));
    if (row < 0 || row >= rows_) return -1;
    Scalar u = static_cast<Scalar>((azimuth - azimuth_start_) * inverse_azimuth_step_);
    const auto period = static_cast<Scalar>(period_columns_);
    u -= period * std::floor(u / period);        // into [0, period)
    if (u >= period - Scalar(0.5)) u -= period;  // the seam: nearer to column 0
    const auto col = static_cast<std::int64_t>(std::floor(u + Scalar(0.5)));
    if (col < 0 || col >= columns_) return -1;
    return row * columns_ + col;
  }

 private:
  std::int64_t rows_ = 0;
  std::int64_t columns_ = 0;
  double azimuth_start_ = 0.0;
  double elevation_start_ = 0.0;
  double inverse_azimuth_step_ = 0.0;
  double inverse_elevation_step_ = 0.0;
  double period_columns_ = 0.0;  // columns in a full turn
};

}  // namespace scanbench::registration

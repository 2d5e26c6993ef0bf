// Projective data association for panoramic scans: the pixel whose beam a
// point lies on, in constant time. The scan's own angular grid is the index,
// so no kd-tree is built.
#pragma once

#include <Eigen/Core>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <type_traits>

#include "acquisition/geometry/fast_atan2.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

class SphericalGrid {
 public:
  // Asserts that `scan` has a spherical angle model with non-zero steps.
  explicit SphericalGrid(const Scan& scan) {
    const auto& model = std::get<SphericalAngles>(scan.angles);
    assert(model.azimuth_step_rad != 0.0 && model.elevation_step_rad != 0.0);
    rows_ = scan.rows;
    columns_ = scan.columns;
    const double inverse_azimuth_step = 1.0 / model.azimuth_step_rad;
    const double period = 2.0 * std::numbers::pi * std::abs(inverse_azimuth_step);
    double_ = {model.azimuth_start_rad,
               model.elevation_start_rad,
               inverse_azimuth_step,
               1.0 / model.elevation_step_rad,
               period,
               1.0 / period};
    float_ = {static_cast<float>(double_.azimuth_start),
              static_cast<float>(double_.elevation_start),
              static_cast<float>(double_.inverse_azimuth_step),
              static_cast<float>(double_.inverse_elevation_step),
              static_cast<float>(double_.period_columns),
              static_cast<float>(double_.inverse_period_columns)};
    half_diagonal_rad_ = 0.5 * std::hypot(model.azimuth_step_rad, model.elevation_step_rad);
  }

  // The largest angle [rad] between a direction and the beam of the pixel it
  // is associated with: half the pixel's diagonal.
  double half_diagonal_rad() const { return half_diagonal_rad_; }

  // Row-major index of the pixel whose beam is nearest to the direction of
  // `p_scan` (a point in the scan frame [m], float or double), or -1 when the
  // direction lies outside the grid or p_scan is the origin. Panoramas that
  // close the full circle wrap around in azimuth.
  template <typename Scalar>
  std::int64_t pixel_of(const Eigen::Matrix<Scalar, 3, 1>& p_scan) const {
    const Scalar horizontal = std::sqrt(p_scan.x() * p_scan.x() + p_scan.y() * p_scan.y());
    if (horizontal == Scalar(0) && p_scan.z() == Scalar(0)) return -1;
    const Scalar azimuth = atan2_of(p_scan.y(), p_scan.x());
    const Scalar elevation = atan2_of(p_scan.z(), horizontal);
    const Angles<Scalar>& a = angles<Scalar>();
    const Scalar v = (elevation - a.elevation_start) * a.inverse_elevation_step;
    if (!(v >= Scalar(-0.5))) return -1;  // above the first row (or not a number)
    const auto row =
        static_cast<std::int64_t>(v + Scalar(0.5));  // v + ½ ≥ 0: truncation rounds down
    if (row >= rows_) return -1;
    Scalar u = (azimuth - a.azimuth_start) * a.inverse_azimuth_step;
    const Scalar period = a.period_columns;
    u -= period * std::floor(u * a.inverse_period_columns);       // into [0, period)
    if (u >= period - Scalar(0.5)) u -= period;                   // the seam: nearer to column 0
    const auto col = static_cast<std::int64_t>(u + Scalar(0.5));  // u ≥ −½
    if (col >= columns_) return -1;
    return row * columns_ + col;
  }

 private:
  // Floats (the association of samples and merged points) take the fast
  // polynomial; doubles the library's atan2.
  template <typename Scalar>
  static Scalar atan2_of(Scalar y, Scalar x) {
    if constexpr (std::is_same_v<Scalar, float>) {
      return fast_atan2(y, x);
    } else {
      return std::atan2(y, x);
    }
  }

  // The angle model in the precision of the points projected.
  template <typename Scalar>
  struct Angles {
    Scalar azimuth_start = 0;  // [rad]
    Scalar elevation_start = 0;
    Scalar inverse_azimuth_step = 0;  // [1/rad]
    Scalar inverse_elevation_step = 0;
    Scalar period_columns = 0;  // columns in a full turn
    Scalar inverse_period_columns = 0;
  };

  template <typename Scalar>
  const Angles<Scalar>& angles() const {
    if constexpr (std::is_same_v<Scalar, float>) {
      return float_;
    } else {
      return double_;
    }
  }

  std::int64_t rows_ = 0;
  std::int64_t columns_ = 0;
  Angles<double> double_;
  Angles<float> float_;
  double half_diagonal_rad_ = 0.0;
};

}  // namespace scanbench::acquisition

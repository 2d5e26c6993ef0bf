#include "acquisition/grid_covariance.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace scanbench::acquisition {

GridDirections::GridDirections(const Scan& scan) : columns(scan.columns) {
  if (const auto* p = std::get_if<PerPixelDirections>(&scan.angles)) {
    per_pixel = p->directions.data();
    return;
  }
  const auto& a = std::get<SphericalAngles>(scan.angles);
  for (int col = 0; col < scan.columns; ++col) {
    const double az = a.azimuth_start_rad + col * a.azimuth_step_rad;
    cos_az.push_back(static_cast<float>(std::cos(az)));
    sin_az.push_back(static_cast<float>(std::sin(az)));
  }
  for (int row = 0; row < scan.rows; ++row) {
    const double el = a.elevation_start_rad + row * a.elevation_step_rad;
    cos_el.push_back(static_cast<float>(std::cos(el)));
    sin_el.push_back(static_cast<float>(std::sin(el)));
  }
}

NormalFit covariance_fit(const GridDirections& directions, const float* range_m,
                         const std::uint8_t* mask, const float* log_range, int row, int col,
                         int rows, const GeometrySettings& settings) {
  const int k = settings.edge_window_radius, columns = directions.columns;
  const std::size_t centre_index = static_cast<std::size_t>(row) * columns + col;
  const float centre = log_range[centre_index];
  const Eigen::Vector3f view = directions.at(row, col);
  const Eigen::Vector3f origin = range_m[centre_index] * view;  // sums relative to it stay small
  const auto relative = static_cast<float>(settings.depth_jump_relative);
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  NormalFit fit;
  fit.window = (2 * k + 1) * (2 * k + 1);
  const int col_begin = std::max(0, col - k), col_end = std::min(columns - 1, col + k);
  for (int r = std::max(0, row - k); r <= std::min(rows - 1, row + k); ++r) {
    const std::size_t offset = static_cast<std::size_t>(r) * columns;
    for (int c = col_begin; c <= col_end; ++c) {
      const std::size_t i = offset + c;
      const float limit =
          relative * static_cast<float>(std::max(std::abs(r - row), std::abs(c - col))) + 1e-7f;
      if (!mask[i] || std::abs(log_range[i] - centre) > limit) continue;
      const Eigen::Vector3f p = range_m[i] * directions.at(r, c) - origin;
      sum += p;
      xx += p.x() * p.x(), xy += p.x() * p.y(), xz += p.x() * p.z();
      yy += p.y() * p.y(), yz += p.y() * p.z(), zz += p.z() * p.z();
      ++fit.used;
    }
  }
  if (fit.used < 3) return fit;
  const Eigen::Vector3f mean = sum / static_cast<float>(fit.used);
  Eigen::Matrix3f covariance;
  covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  covariance = covariance / static_cast<float>(fit.used) - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3f& values = solver.eigenvalues();
  if (values[1] <= 4.0f * values[0]) return fit;  // a line or a blob, not a surface
  fit.normal = solver.eigenvectors().col(0).normalized();
  if (fit.normal.dot(origin) > 0) fit.normal = -fit.normal;
  fit.cos_incidence = std::abs(fit.normal.dot(view));
  fit.ok = true;
  return fit;
}

}  // namespace scanbench::acquisition

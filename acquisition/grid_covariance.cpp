#include "acquisition/grid_covariance.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
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

namespace {

// The smallest eigenvalue of a symmetric 3 × 3 matrix with trace 1, its
// eigenvector, and the middle eigenvalue; false when the smallest eigenvalue
// is not separated (the eigenvector is then undefined).
//
// Why not a general solver: the closed form needs acos, cos and sin, and
// dominated the fallback's time. The characteristic polynomial
// p(λ) = λ³ − λ² + c1·λ − c0 (c1: sum of the principal 2 × 2 minors, c0: the
// determinant) is increasing and concave left of its smallest root λ0
// (p'' < 0 for λ < 1/3 ≥ λ0), so Newton's method started left of λ0 climbs
// to it monotonically, quadratically fast when λ0 is a simple root — the
// planar case; a blob or a line is rejected anyway. λ1 and λ2 then solve
// λ1 + λ2 = 1 − λ0, λ1·λ2 = c1 − λ0·(1 − λ0), and the eigenvector is the
// longest cross product of two rows of C − λ0·I (a rank-2 matrix).
bool smallest_eigenpair(const Eigen::Matrix3d& a, Eigen::Vector3d& vector, double& smallest,
                        double& middle) {
  const double c1 = a(0, 0) * a(1, 1) - a(0, 1) * a(0, 1) + a(0, 0) * a(2, 2) - a(0, 2) * a(0, 2) +
                    a(1, 1) * a(2, 2) - a(1, 2) * a(1, 2);
  const double c0 = a.determinant();
  // Start at 0 unless rounding made the matrix slightly indefinite (c0 < 0);
  // then at the Gershgorin bound, which is left of every eigenvalue.
  double lambda = 0.0;
  if (c0 < 0.0) {
    for (int i = 0; i < 3; ++i)
      lambda =
          std::min(lambda, a(i, i) - std::abs(a(i, (i + 1) % 3)) - std::abs(a(i, (i + 2) % 3)));
  }
  for (int iteration = 0; iteration < 40; ++iteration) {
    const double p = ((lambda - 1.0) * lambda + c1) * lambda - c0;
    const double slope = (3.0 * lambda - 2.0) * lambda + c1;
    if (!(slope > 0.0)) break;
    const double step = p / slope;
    lambda -= step;
    if (std::abs(step) <= 1e-15) break;
  }
  const double sum = 1.0 - lambda, product = c1 - lambda * sum;
  const double root = std::sqrt(std::max(0.0, sum * sum - 4.0 * product));
  smallest = lambda;
  middle = sum + root > 0.0 ? 2.0 * product / (sum + root) : 0.0;
  const Eigen::Matrix3d shifted = a - lambda * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d r0 = shifted.row(0), r1 = shifted.row(1), r2 = shifted.row(2);
  const Eigen::Vector3d candidates[3] = {r0.cross(r1), r0.cross(r2), r1.cross(r2)};
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (candidates[i].squaredNorm() > candidates[best].squaredNorm()) best = i;
  const double length = candidates[best].norm();
  if (!(length > 0.0)) return false;
  vector = candidates[best] / length;
  return true;
}

}  // namespace

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
  const double trace = covariance.trace();
  if (!(trace > 0.0)) return fit;
  Eigen::Vector3d normal;
  double smallest = 0.0, middle = 0.0;
  if (!smallest_eigenpair(covariance.cast<double>() / trace, normal, smallest, middle) ||
      middle <= 4.0 * smallest)  // a line or a blob, not a surface
    return fit;
  fit.normal = normal.cast<float>();
  if (fit.normal.dot(origin) > 0) fit.normal = -fit.normal;
  fit.cos_incidence = std::abs(fit.normal.dot(view));
  fit.ok = true;
  return fit;
}

}  // namespace scanbench::acquisition

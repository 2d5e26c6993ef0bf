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

// Whether the symmetric positive semidefinite 3 × 3 matrix `a` with trace 1
// is a plane's covariance — middle eigenvalue λ1 more than 4 × the smallest
// λ0 — and then the eigenvector of λ0.
//
// Why not a general solver: the closed form needs acos, cos and sin, and a
// Newton loop for λ0 is a chain of dependent divisions; both dominated the
// fallback's time. Here, with c1 the sum of the principal 2 × 2 minors and
// c0 the determinant (the characteristic polynomial is
// λ³ − λ² + c1·λ − c0):
// 1. σ = c0 / c1, one Newton step from 0, lies just left of λ0 (the
//    polynomial is concave and increasing there): λ0 − σ ≈ λ0·(λ0/λ1 + λ0/λ2).
// 2. The adjugate of a − σ·I has the same eigenvectors, with the one of λ0 by
//    far the largest eigenvalue, (λ1 − σ)(λ2 − σ) against (λ0 − σ)(λ2 − σ):
//    its longest column (a cross product of two rows of a − σ·I) is already
//    close to it, and each power step with it multiplies the error by
//    r = (λ0 − σ)/(λ1 − σ) ≈ λ0²/λ1²: after two steps it is about r³,
//    ~10⁻¹² rad on a plane sampled with noise and below 10⁻³ rad even at the
//    planarity limit λ1 = 4·λ0, where r ≤ 0.1.
// 3. λ0 is the Rayleigh quotient; λ1, λ2 solve t² − s·t + q = 0 with
//    s = 1 − λ0, q = c1 − λ0·s, and λ1 > 4·λ0 holds exactly when that
//    quadratic is positive at 4·λ0 with its vertex s/2 to the right of it.
bool plane_normal(const Eigen::Matrix3d& a, Eigen::Vector3d& normal) {
  const double c1 = a(0, 0) * a(1, 1) - a(0, 1) * a(0, 1) + a(0, 0) * a(2, 2) - a(0, 2) * a(0, 2) +
                    a(1, 1) * a(2, 2) - a(1, 2) * a(1, 2);
  if (!(c1 > 0.0)) return false;  // rank ≤ 1: a line or a point
  const double sigma = a.determinant() / c1;
  const Eigen::Matrix3d shifted = a - sigma * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d r0 = shifted.row(0), r1 = shifted.row(1), r2 = shifted.row(2);
  Eigen::Matrix3d adjugate;  // symmetric: its columns are these cross products
  adjugate << r1.cross(r2), r2.cross(r0), r0.cross(r1);
  Eigen::Index longest = 0;
  adjugate.colwise().squaredNorm().maxCoeff(&longest);
  Eigen::Vector3d v = adjugate * (adjugate * adjugate.col(longest));
  const double length = v.norm();
  if (!(length > 0.0)) return false;
  normal = v / length;
  const double smallest = normal.dot(a * normal);
  const double s = 1.0 - smallest, q = c1 - smallest * s, t = 4.0 * smallest;
  return t < 0.5 * s && (t - s) * t + q > 0.0;
}

// Directions of a spherical scan's pixels as products of its tables; a
// functor so that the gather below has no branch on the grid type.
struct SphericalDirection {
  const GridDirections& d;
  Eigen::Vector3f operator()(int row, int col) const {
    return {d.cos_el[row] * d.cos_az[col], d.cos_el[row] * d.sin_az[col], d.sin_el[row]};
  }
};

struct PerPixelDirection {
  const GridDirections& d;
  Eigen::Vector3f operator()(int row, int col) const { return d.at(row, col); }
};

// Sums of the consistent neighbours' points relative to `origin`, then the
// plane through them. Branch-free over the window (a rejected neighbour adds
// zeros): which neighbours pass depends on the data, and a mispredicted
// branch per neighbour cost more than the arithmetic it saves.
template <typename Direction>
NormalFit fit_window(const Direction& direction, const float* range_m, const std::uint8_t* mask,
                     const float* log_range, int row, int col, int rows, int columns,
                     const GeometrySettings& settings) {
  const int k = settings.edge_window_radius;
  const std::size_t centre_index = static_cast<std::size_t>(row) * columns + col;
  const float centre = log_range[centre_index];
  const Eigen::Vector3f view = direction(row, col);
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
      const bool take = mask[i] && std::abs(log_range[i] - centre) <= limit;
      const Eigen::Vector3f p =
          take ? Eigen::Vector3f(range_m[i] * direction(r, c) - origin) : Eigen::Vector3f::Zero();
      sum += p;
      xx += p.x() * p.x(), xy += p.x() * p.y(), xz += p.x() * p.z();
      yy += p.y() * p.y(), yz += p.y() * p.z(), zz += p.z() * p.z();
      fit.used += take;
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
  if (!plane_normal(covariance.cast<double>() / trace, normal)) return fit;
  fit.normal = normal.cast<float>();
  if (fit.normal.dot(origin) > 0) fit.normal = -fit.normal;
  fit.cos_incidence = std::abs(fit.normal.dot(view));
  fit.ok = true;
  return fit;
}

}  // namespace

NormalFit covariance_fit(const GridDirections& directions, const float* range_m,
                         const std::uint8_t* mask, const float* log_range, int row, int col,
                         int rows, const GeometrySettings& settings) {
  if (directions.per_pixel != nullptr) {
    return fit_window(PerPixelDirection{directions}, range_m, mask, log_range, row, col, rows,
                      directions.columns, settings);
  }
  return fit_window(SphericalDirection{directions}, range_m, mask, log_range, row, col, rows,
                    directions.columns, settings);
}

}  // namespace scanbench::acquisition

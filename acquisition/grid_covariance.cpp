#include "acquisition/grid_covariance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "acquisition/branch_free.hpp"

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
//
// Plain scalars on the six unique entries: Eigen's fixed 3 × 3 double
// products compile into packet shuffles that cost more than the arithmetic.
struct Symmetric3 {
  double xx, xy, xz, yy, yz, zz;

  Eigen::Vector3d times(const Eigen::Vector3d& v) const {
    return {xx * v.x() + xy * v.y() + xz * v.z(), xy * v.x() + yy * v.y() + yz * v.z(),
            xz * v.x() + yz * v.y() + zz * v.z()};
  }
};

bool plane_normal(const Symmetric3& a, Eigen::Vector3d& normal) {
  const double c1 =
      a.xx * a.yy - a.xy * a.xy + a.xx * a.zz - a.xz * a.xz + a.yy * a.zz - a.yz * a.yz;
  if (!(c1 > 0.0)) return false;  // rank ≤ 1: a line or a point
  const double c0 = a.xx * (a.yy * a.zz - a.yz * a.yz) - a.xy * (a.xy * a.zz - a.yz * a.xz) +
                    a.xz * (a.xy * a.yz - a.yy * a.xz);
  const double sigma = c0 / c1;
  const double bx = a.xx - sigma, by = a.yy - sigma, bz = a.zz - sigma;
  // The adjugate of a − σ·I (symmetric, so its columns are also its rows).
  const Symmetric3 adjugate{by * bz - a.yz * a.yz, a.xz * a.yz - a.xy * bz, a.xy * a.yz - a.xz * by,
                            bx * bz - a.xz * a.xz, a.xy * a.xz - bx * a.yz, bx * by - a.xy * a.xy};
  const Eigen::Vector3d columns[3] = {{adjugate.xx, adjugate.xy, adjugate.xz},
                                      {adjugate.xy, adjugate.yy, adjugate.yz},
                                      {adjugate.xz, adjugate.yz, adjugate.zz}};
  int longest = 0;
  for (int i = 1; i < 3; ++i)
    if (columns[i].squaredNorm() > columns[longest].squaredNorm()) longest = i;
  const Eigen::Vector3d v = adjugate.times(adjugate.times(columns[longest]));
  const double length = v.norm();
  if (!(length > 0.0)) return false;
  normal = v * (1.0 / length);
  const double smallest = normal.dot(a.times(normal));
  const double s = 1.0 - smallest, q = c1 - smallest * s, t = 4.0 * smallest;
  return t < 0.5 * s && (t - s) * t + q > 0.0;
}

// Sums of the consistent neighbours' points relative to the centre's point.
struct PointSums {
  float x = 0, y = 0, z = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  int used = 0;
};

// The plane through the gathered points (see plane_normal), its normal
// turned towards the scanner.
NormalFit plane_from_sums(const PointSums& s, const Eigen::Vector3f& origin,
                          const Eigen::Vector3f& view, int window) {
  NormalFit fit;
  fit.window = window;
  fit.used = s.used;
  if (s.used < 3) return fit;
  // The covariance in double from the float sums, normalised to trace 1;
  // reciprocals, not the 18 divisions of the plain expression.
  const double inverse_n = 1.0 / s.used;
  const double mx = s.x * inverse_n, my = s.y * inverse_n, mz = s.z * inverse_n;
  const double xx = s.xx * inverse_n - mx * mx, yy = s.yy * inverse_n - my * my,
               zz = s.zz * inverse_n - mz * mz, xy = s.xy * inverse_n - mx * my,
               xz = s.xz * inverse_n - mx * mz, yz = s.yz * inverse_n - my * mz;
  const double trace = xx + yy + zz;
  if (!(trace > 0.0)) return fit;
  const double t = 1.0 / trace;
  Eigen::Vector3d normal;
  if (!plane_normal({xx * t, xy * t, xz * t, yy * t, yz * t, zz * t}, normal)) return fit;
  fit.normal = normal.cast<float>();
  if (fit.normal.dot(origin) > 0) fit.normal = -fit.normal;
  fit.cos_incidence = std::abs(fit.normal.dot(view));
  fit.ok = true;
  return fit;
}

// Largest log-range difference to the centre of a consistent neighbour at
// Chebyshev distance `distance` (+ a rounding margin).
float consistency_limit(const GeometrySettings& settings, int distance) {
  return static_cast<float>(settings.depth_jump_relative) * static_cast<float>(distance) + 1e-7f;
}

// One pixel's window, clipped to the grid; a rejected neighbour adds zeros,
// so the sums equal those of covariance_fits' lanes bit for bit.
template <typename Direction>
NormalFit fit_window(const Direction& direction, const float* range_m, const std::uint8_t* mask,
                     const float* log_range, int row, int col, int rows, int columns,
                     const GeometrySettings& settings) {
  const int k = settings.edge_window_radius;
  const std::size_t centre_index = static_cast<std::size_t>(row) * columns + col;
  const float centre = log_range[centre_index];
  const Eigen::Vector3f view = direction(row, col);
  const Eigen::Vector3f origin = range_m[centre_index] * view;  // sums relative to it stay small
  PointSums s;
  const int col_begin = std::max(0, col - k), col_end = std::min(columns - 1, col + k);
  for (int r = std::max(0, row - k); r <= std::min(rows - 1, row + k); ++r) {
    const std::size_t offset = static_cast<std::size_t>(r) * columns;
    for (int c = col_begin; c <= col_end; ++c) {
      const std::size_t i = offset + c;
      const float limit =
          consistency_limit(settings, std::max(std::abs(r - row), std::abs(c - col)));
      const bool take = mask[i] && std::abs(log_range[i] - centre) <= limit;
      if (!take) continue;
      const Eigen::Vector3f p = range_m[i] * direction(r, c) - origin;
      s.x += p.x(), s.y += p.y(), s.z += p.z();
      s.xx += p.x() * p.x(), s.xy += p.x() * p.y(), s.xz += p.x() * p.z();
      s.yy += p.y() * p.y(), s.yz += p.y() * p.z(), s.zz += p.z() * p.z();
      ++s.used;
    }
  }
  return plane_from_sums(s, origin, view, (2 * k + 1) * (2 * k + 1));
}

// The sums of kCovarianceLanes horizontally adjacent centres, one lane each.
struct LaneSums {
  float x[kCovarianceLanes] = {}, y[kCovarianceLanes] = {}, z[kCovarianceLanes] = {};
  float xx[kCovarianceLanes] = {}, xy[kCovarianceLanes] = {}, xz[kCovarianceLanes] = {};
  float yy[kCovarianceLanes] = {}, yz[kCovarianceLanes] = {}, zz[kCovarianceLanes] = {};
  std::int32_t used[kCovarianceLanes] = {};
};

// What the lanes' centres contribute to every neighbour's test and point.
struct LaneCentres {
  float log_range[kCovarianceLanes], x[kCovarianceLanes], y[kCovarianceLanes], z[kCovarianceLanes];
};

// One window offset for all lanes: their neighbours are consecutive pixels
// of one row. Branch-free over plain, unaliased arrays, so that it
// vectorizes; the same operations in the same order as fit_window. The mask
// is not read: log_range is NaN where it is 0, which fails the comparison.
void add_offset(const float* __restrict range, const float* __restrict log_range,
                const float* __restrict cos_az, const float* __restrict sin_az, float cos_el,
                float sin_el, float limit, const LaneCentres& __restrict centres,
                LaneSums& __restrict s) {
  for (int j = 0; j < kCovarianceLanes; ++j) {
    const bool take = std::abs(log_range[j] - centres.log_range[j]) <= limit;
    const std::uint32_t keep = all_bits(take);
    const float px = select_bits(range[j] * (cos_el * cos_az[j]) - centres.x[j], keep);
    const float py = select_bits(range[j] * (cos_el * sin_az[j]) - centres.y[j], keep);
    const float pz = select_bits(range[j] * sin_el - centres.z[j], keep);
    s.x[j] += px, s.y[j] += py, s.z[j] += pz;
    s.xx[j] += px * px, s.xy[j] += px * py, s.xz[j] += px * pz;
    s.yy[j] += py * py, s.yz[j] += py * pz, s.zz[j] += pz * pz;
    s.used[j] += take;
  }
}

}  // namespace

NormalFit covariance_fit(const GridDirections& directions, const float* range_m,
                         const std::uint8_t* mask, const float* log_range, int row, int col,
                         int rows, const GeometrySettings& settings) {
  const int columns = directions.columns;
  if (directions.per_pixel != nullptr) {
    return fit_window([&](int r, int c) { return directions.at(r, c); }, range_m, mask, log_range,
                      row, col, rows, columns, settings);
  }
  const auto spherical = [&](int r, int c) -> Eigen::Vector3f {
    return {directions.cos_el[r] * directions.cos_az[c],
            directions.cos_el[r] * directions.sin_az[c], directions.sin_el[r]};
  };
  return fit_window(spherical, range_m, mask, log_range, row, col, rows, columns, settings);
}

bool covariance_lanes_fit(const GridDirections& directions, int row, int col, int rows,
                          const GeometrySettings& settings) {
  const int k = settings.edge_window_radius;
  return directions.per_pixel == nullptr && row - k >= 0 && row + k < rows && col - k >= 0 &&
         col + kCovarianceLanes - 1 + k < directions.columns;
}

void covariance_fits(const GridDirections& directions, const float* range_m, const float* log_range,
                     int row, int col, [[maybe_unused]] int rows, const GeometrySettings& settings,
                     unsigned wanted, NormalFit* fits) {
  assert(covariance_lanes_fit(directions, row, col, rows, settings) && "lanes inside the grid");
  const int k = settings.edge_window_radius, columns = directions.columns;
  const std::size_t centre_index = static_cast<std::size_t>(row) * columns + col;
  LaneCentres centres;
  Eigen::Vector3f views[kCovarianceLanes], origins[kCovarianceLanes];
  for (int j = 0; j < kCovarianceLanes; ++j) {
    views[j] = directions.at(row, col + j);
    origins[j] = range_m[centre_index + j] * views[j];
    centres.log_range[j] = log_range[centre_index + j];
    centres.x[j] = origins[j].x(), centres.y[j] = origins[j].y(), centres.z[j] = origins[j].z();
  }
  LaneSums s;
  for (int r = row - k; r <= row + k; ++r) {
    for (int dc = -k; dc <= k; ++dc) {
      const std::size_t i = static_cast<std::size_t>(r) * columns + col + dc;
      add_offset(range_m + i, log_range + i, directions.cos_az.data() + col + dc,
                 directions.sin_az.data() + col + dc, directions.cos_el[r], directions.sin_el[r],
                 consistency_limit(settings, std::max(std::abs(r - row), std::abs(dc))), centres,
                 s);
    }
  }
  for (int j = 0; j < kCovarianceLanes; ++j) {
    if ((wanted & (1u << j)) == 0) continue;
    const PointSums lane{s.x[j],  s.y[j],  s.z[j],  s.xx[j], s.xy[j],
                         s.xz[j], s.yy[j], s.yz[j], s.zz[j], s.used[j]};
    fits[j] = plane_from_sums(lane, origins[j], views[j], (2 * k + 1) * (2 * k + 1));
  }
}

}  // namespace scanbench::acquisition

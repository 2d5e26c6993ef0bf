#include "acquisition/grid_covariance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "acquisition/branch_free.hpp"

namespace scanbench::acquisition {

GridDirections::GridDirections(const Scan& scan) : columns(scan.columns) {
  if (const auto* p = std::get_if<PerPixelDirections>(&scan.angles)) {
    per_pixel = p->directions;
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

// The sums of the consistent neighbours' points relative to the centre's
// point, for kCovarianceLanes centres at once (one lane each).
struct LaneSums {
  float x[kCovarianceLanes] = {}, y[kCovarianceLanes] = {}, z[kCovarianceLanes] = {};
  float xx[kCovarianceLanes] = {}, xy[kCovarianceLanes] = {}, xz[kCovarianceLanes] = {};
  float yy[kCovarianceLanes] = {}, yz[kCovarianceLanes] = {}, zz[kCovarianceLanes] = {};
  std::int32_t used[kCovarianceLanes] = {};
};

// The lanes' centres: log-range, point (the origin of the sums) and viewing
// direction.
struct LaneCentres {
  float log_range[kCovarianceLanes] = {}, x[kCovarianceLanes] = {}, y[kCovarianceLanes] = {},
        z[kCovarianceLanes] = {};
  float view_x[kCovarianceLanes] = {}, view_y[kCovarianceLanes] = {}, view_z[kCovarianceLanes] = {};
};

// The planes through each lane's points: unit normals towards the scanner.
struct LanePlanes {
  float x[kCovarianceLanes], y[kCovarianceLanes], z[kCovarianceLanes];
  float cos_incidence[kCovarianceLanes];
  std::int32_t ok[kCovarianceLanes];
};

// `value` where `keep`, else 1: a divisor that is never 0 (branch-free).
inline double or_one(double value, bool keep) {
  return select_bits64(value, all_bits64(keep)) + select_bits64(1.0, all_bits64(!keep));
}

// For each lane: the covariance of its points normalised to trace 1, a
// symmetric positive semidefinite 3 × 3 matrix a; whether it is a plane's —
// middle eigenvalue λ1 more than 4 × the smallest λ0 — and then the
// eigenvector of λ0, turned towards the scanner.
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
// In double precision, branch-free over the lanes so that it vectorizes
// (every lane is computed; unused ones cost nothing extra).
SCANBENCH_VECTOR_CLONES void lane_planes(const LaneSums& __restrict s,
                                         const LaneCentres& __restrict c,
                                         LanePlanes& __restrict out) {
  for (int j = 0; j < kCovarianceLanes; ++j) {
    bool ok = s.used[j] >= 3;
    const double inverse_n = 1.0 / std::max(s.used[j], 1);
    const double mx = s.x[j] * inverse_n, my = s.y[j] * inverse_n, mz = s.z[j] * inverse_n;
    const double cxx = s.xx[j] * inverse_n - mx * mx, cyy = s.yy[j] * inverse_n - my * my,
                 czz = s.zz[j] * inverse_n - mz * mz, cxy = s.xy[j] * inverse_n - mx * my,
                 cxz = s.xz[j] * inverse_n - mx * mz, cyz = s.yz[j] * inverse_n - my * mz;
    const double trace = cxx + cyy + czz;
    ok &= trace > 0.0;
    const double t = 1.0 / or_one(trace, trace > 0.0);
    const double xx = cxx * t, yy = cyy * t, zz = czz * t, xy = cxy * t, xz = cxz * t, yz = cyz * t;
    const double c1 = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
    ok &= c1 > 0.0;  // else rank ≤ 1: a line or a point
    const double c0 =
        xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
    const double sigma = c0 / or_one(c1, c1 > 0.0);
    const double bx = xx - sigma, by = yy - sigma, bz = zz - sigma;
    // The adjugate of a − σ·I (symmetric: its columns are also its rows).
    const double axx = by * bz - yz * yz, axy = xz * yz - xy * bz, axz = xy * yz - xz * by,
                 ayy = bx * bz - xz * xz, ayz = xy * xz - bx * yz, azz = bx * by - xy * xy;
    const double n0 = axx * axx + axy * axy + axz * axz, n1 = axy * axy + ayy * ayy + ayz * ayz,
                 n2 = axz * axz + ayz * ayz + azz * azz;
    const std::uint64_t take1 = all_bits64(n1 > n0);
    const std::uint64_t take2 = all_bits64(n2 > std::max(n0, n1));
    const std::uint64_t take0 = ~(take1 | take2), only1 = take1 & ~take2;
    const double ux =
        select_bits64(axx, take0) + select_bits64(axy, only1) + select_bits64(axz, take2);
    const double uy =
        select_bits64(axy, take0) + select_bits64(ayy, only1) + select_bits64(ayz, take2);
    const double uz =
        select_bits64(axz, take0) + select_bits64(ayz, only1) + select_bits64(azz, take2);
    const double wx = axx * ux + axy * uy + axz * uz, wy = axy * ux + ayy * uy + ayz * uz,
                 wz = axz * ux + ayz * uy + azz * uz;
    double vx = axx * wx + axy * wy + axz * wz, vy = axy * wx + ayy * wy + ayz * wz,
           vz = axz * wx + ayz * wy + azz * wz;
    // Normalise: scaled to its largest entry first, so the float estimate of
    // 1/√q is in range, then one Newton step in double.
    const double largest = std::max(std::max(std::abs(vx), std::abs(vy)), std::abs(vz));
    ok &= largest > 0.0;
    const double scale = 1.0 / or_one(largest, largest > 0.0);
    vx *= scale, vy *= scale, vz *= scale;
    const double q = vx * vx + vy * vy + vz * vz;
    double inverse = inverse_sqrt(static_cast<float>(q));
    inverse *= 1.5 - 0.5 * q * inverse * inverse;
    vx *= inverse, vy *= inverse, vz *= inverse;
    const double smallest = vx * (xx * vx + xy * vy + xz * vz) +
                            vy * (xy * vx + yy * vy + yz * vz) + vz * (xz * vx + yz * vy + zz * vz);
    const double sum = 1.0 - smallest, product = c1 - smallest * sum, t4 = 4.0 * smallest;
    ok &= (t4 < 0.5 * sum) & ((t4 - sum) * t4 + product > 0.0);
    const float nx = static_cast<float>(vx), ny = static_cast<float>(vy),
                nz = static_cast<float>(vz);
    const float away = nx * c.x[j] + ny * c.y[j] + nz * c.z[j];  // > 0: faces away
    const float sign =
        select_bits(-1.0f, all_bits(away > 0.0f)) + select_bits(1.0f, all_bits(!(away > 0.0f)));
    out.x[j] = sign * nx, out.y[j] = sign * ny, out.z[j] = sign * nz;
    out.cos_incidence[j] = std::abs(nx * c.view_x[j] + ny * c.view_y[j] + nz * c.view_z[j]);
    out.ok[j] = ok;
  }
}

// Lane j's result as a NormalFit.
NormalFit lane_fit(const LaneSums& s, const LanePlanes& planes, int j, int window) {
  NormalFit fit;
  fit.window = window;
  fit.used = s.used[j];
  if (!planes.ok[j]) return fit;
  fit.normal = Eigen::Vector3f(planes.x[j], planes.y[j], planes.z[j]);
  fit.cos_incidence = planes.cos_incidence[j];
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
  LaneSums s;                                                   // lane 0 only
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
      s.x[0] += p.x(), s.y[0] += p.y(), s.z[0] += p.z();
      s.xx[0] += p.x() * p.x(), s.xy[0] += p.x() * p.y(), s.xz[0] += p.x() * p.z();
      s.yy[0] += p.y() * p.y(), s.yz[0] += p.y() * p.z(), s.zz[0] += p.z() * p.z();
      ++s.used[0];
    }
  }
  LaneCentres centres;
  centres.x[0] = origin.x(), centres.y[0] = origin.y(), centres.z[0] = origin.z();
  centres.view_x[0] = view.x(), centres.view_y[0] = view.y(), centres.view_z[0] = view.z();
  LanePlanes planes;
  lane_planes(s, centres, planes);
  return lane_fit(s, planes, 0, (2 * k + 1) * (2 * k + 1));
}

// One window offset for all lanes: their neighbours are consecutive pixels
// of one row. Branch-free over plain, unaliased arrays, so that it
// vectorizes; the same operations in the same order as fit_window. The mask
// is not read: log_range is NaN where it is 0, which fails the comparison.
void add_offset(const float* __restrict range, const float* __restrict log_range,
                const float* __restrict cos_az, const float* __restrict sin_az, float cos_el,
                float sin_el, float limit, const float* __restrict centre_log_range,
                const float* __restrict centre_x, const float* __restrict centre_y,
                const float* __restrict centre_z, LaneSums& __restrict s) {
  for (int j = 0; j < kCovarianceLanes; ++j) {
    const bool take = std::abs(log_range[j] - centre_log_range[j]) <= limit;
    const std::uint32_t keep = all_bits(take);
    const float px = select_bits(range[j] * (cos_el * cos_az[j]) - centre_x[j], keep);
    const float py = select_bits(range[j] * (cos_el * sin_az[j]) - centre_y[j], keep);
    const float pz = select_bits(range[j] * sin_el - centre_z[j], keep);
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
  if (directions.is_per_pixel()) {
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
  return !directions.is_per_pixel() && row - k >= 0 && row + k < rows && col - k >= 0 &&
         col + kCovarianceLanes - 1 + k < directions.columns;
}

void covariance_fits(const GridDirections& directions, const float* range_m, const float* log_range,
                     int row, int col, [[maybe_unused]] int rows, const GeometrySettings& settings,
                     unsigned wanted, NormalFit* fits) {
  assert(covariance_lanes_fit(directions, row, col, rows, settings) && "lanes inside the grid");
  const int k = settings.edge_window_radius, columns = directions.columns;
  const std::size_t centre_index = static_cast<std::size_t>(row) * columns + col;
  LaneCentres centres;
  for (int j = 0; j < kCovarianceLanes; ++j) {
    const Eigen::Vector3f view = directions.at(row, col + j);
    const Eigen::Vector3f origin = range_m[centre_index + j] * view;
    centres.log_range[j] = log_range[centre_index + j];
    centres.x[j] = origin.x(), centres.y[j] = origin.y(), centres.z[j] = origin.z();
    centres.view_x[j] = view.x(), centres.view_y[j] = view.y(), centres.view_z[j] = view.z();
  }
  LaneSums s;
  for (int r = row - k; r <= row + k; ++r) {
    for (int dc = -k; dc <= k; ++dc) {
      const std::size_t i = static_cast<std::size_t>(r) * columns + col + dc;
      add_offset(range_m + i, log_range + i, directions.cos_az.data() + col + dc,
                 directions.sin_az.data() + col + dc, directions.cos_el[r], directions.sin_el[r],
                 consistency_limit(settings, std::max(std::abs(r - row), std::abs(dc))),
                 centres.log_range, centres.x, centres.y, centres.z, s);
    }
  }
  // A copy goes to the solver, so that `s` itself never escapes this
  // function (otherwise GCC no longer vectorizes add_offset's lanes).
  const LaneSums sums = s;
  LanePlanes planes;
  lane_planes(sums, centres, planes);
  for (int j = 0; j < kCovarianceLanes; ++j) {
    if ((wanted & (1u << j)) != 0) fits[j] = lane_fit(s, planes, j, (2 * k + 1) * (2 * k + 1));
  }
}

}  // namespace scanbench::acquisition

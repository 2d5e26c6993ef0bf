#include "acquisition/geometry/grid_covariance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "acquisition/geometry/branch_free.hpp"

namespace scanbench::acquisition {

GridDirections::GridDirections(const Scan& scan, int first_row) : columns(scan.columns) {
  if (const auto* p = std::get_if<PerPixelDirections>(&scan.angles)) {
    per_pixel = p->directions;
    return;
  }
  const auto& a = std::get<SphericalAngles>(scan.angles);
  for (int col = 0; col < scan.columns; ++col) {
    const double az = a.azimuth(col);
    cos_az.push_back(static_cast<float>(std::cos(az)));
    sin_az.push_back(static_cast<float>(std::sin(az)));
  }
  for (int row = 0; row < scan.rows; ++row) {
    const double el = a.elevation(first_row + row);
    cos_el.push_back(static_cast<float>(std::cos(el)));
    sin_el.push_back(static_cast<float>(std::sin(el)));
  }
}

namespace {

// The sums of the consistent neighbours' points relative to the centre's
// point, for kCovarianceLanes centres at once (one lane each): coordinates
// [m], their products [m²], and the count.
struct LaneSums {
  float x[kCovarianceLanes] = {}, y[kCovarianceLanes] = {}, z[kCovarianceLanes] = {};
  float xx[kCovarianceLanes] = {}, xy[kCovarianceLanes] = {}, xz[kCovarianceLanes] = {};
  float yy[kCovarianceLanes] = {}, yz[kCovarianceLanes] = {}, zz[kCovarianceLanes] = {};
  std::int32_t used[kCovarianceLanes] = {};
};

// The lanes' centres: log-range, point [m] (the origin of the sums) and unit
// viewing direction.
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

// A symmetric 3 × 3 matrix, in double precision.
struct Symmetric3 {
  double xx, xy, xz, yy, yz, zz;
};

struct Vector3 {
  double x, y, z;
};

inline Vector3 times(const Symmetric3& m, const Vector3& v) {
  return {m.xx * v.x + m.xy * v.y + m.xz * v.z, m.xy * v.x + m.yy * v.y + m.yz * v.z,
          m.xz * v.x + m.yz * v.y + m.zz * v.z};
}

// Lane j's covariance normalised to trace 1; `ok` is false with fewer than 3
// points or a zero trace.
struct NormalisedCovariance {
  Symmetric3 a;
  bool ok;
};

inline NormalisedCovariance normalised_covariance(const LaneSums& s, int j) {
  const double inverse_n = 1.0 / std::max(s.used[j], 1);
  const double mx = s.x[j] * inverse_n, my = s.y[j] * inverse_n, mz = s.z[j] * inverse_n;
  const double cxx = s.xx[j] * inverse_n - mx * mx, cyy = s.yy[j] * inverse_n - my * my,
               czz = s.zz[j] * inverse_n - mz * mz, cxy = s.xy[j] * inverse_n - mx * my,
               cxz = s.xz[j] * inverse_n - mx * mz, cyz = s.yz[j] * inverse_n - my * mz;
  const double trace = cxx + cyy + czz;
  const double t = 1.0 / or_one(trace, trace > 0.0);
  const bool ok = (s.used[j] >= 3) & (trace > 0.0);
  return {{cxx * t, cxy * t, cxz * t, cyy * t, cyz * t, czz * t}, ok};
}

// c1 of the characteristic polynomial: the sum of the principal 2 × 2 minors.
inline double minor_sum(const Symmetric3& a) {
  return a.xx * a.yy - a.xy * a.xy + a.xx * a.zz - a.xz * a.xz + a.yy * a.zz - a.yz * a.yz;
}

// c0 of the characteristic polynomial: the determinant.
inline double determinant(const Symmetric3& a) {
  return a.xx * (a.yy * a.zz - a.yz * a.yz) - a.xy * (a.xy * a.zz - a.yz * a.xz) +
         a.xz * (a.xy * a.yz - a.yy * a.xz);
}

// The adjugate of a − σ·I (symmetric: its columns are also its rows).
inline Symmetric3 shifted_adjugate(const Symmetric3& a, double sigma) {
  const double bx = a.xx - sigma, by = a.yy - sigma, bz = a.zz - sigma;
  return {by * bz - a.yz * a.yz, a.xz * a.yz - a.xy * bz, a.xy * a.yz - a.xz * by,
          bx * bz - a.xz * a.xz, a.xy * a.xz - bx * a.yz, bx * by - a.xy * a.xy};
}

// Step 2 below: the longest column of m, then two power steps with m.
inline Vector3 dominant_direction(const Symmetric3& m) {
  const double n0 = m.xx * m.xx + m.xy * m.xy + m.xz * m.xz,
               n1 = m.xy * m.xy + m.yy * m.yy + m.yz * m.yz,
               n2 = m.xz * m.xz + m.yz * m.yz + m.zz * m.zz;
  const std::uint64_t take1 = all_bits64(n1 > n0);
  const std::uint64_t take2 = all_bits64(n2 > std::max(n0, n1));
  const std::uint64_t take0 = ~(take1 | take2), only1 = take1 & ~take2;
  const Vector3 column = {
      select_bits64(m.xx, take0) + select_bits64(m.xy, only1) + select_bits64(m.xz, take2),
      select_bits64(m.xy, take0) + select_bits64(m.yy, only1) + select_bits64(m.yz, take2),
      select_bits64(m.xz, take0) + select_bits64(m.yz, only1) + select_bits64(m.zz, take2)};
  return times(m, times(m, column));
}

// v scaled to unit length; `ok` is false for the zero vector. Scaled to its
// largest entry first, so the float estimate of 1/√q is in range, then one
// Newton step in double.
struct UnitVector {
  Vector3 v;
  bool ok;
};

inline UnitVector normalised(Vector3 v) {
  const double largest = std::max(std::max(std::abs(v.x), std::abs(v.y)), std::abs(v.z));
  const double scale = 1.0 / or_one(largest, largest > 0.0);
  v.x *= scale, v.y *= scale, v.z *= scale;
  const double q = v.x * v.x + v.y * v.y + v.z * v.z;
  double inverse = inverse_sqrt(static_cast<float>(q));
  inverse *= 1.5 - 0.5 * q * inverse * inverse;
  v.x *= inverse, v.y *= inverse, v.z *= inverse;
  return {v, largest > 0.0};
}

// Step 3 below: whether λ1 > 4·λ0, with λ0 the Rayleigh quotient of unit v.
inline bool is_planar(const Symmetric3& a, double c1, const Vector3& v) {
  const Vector3 av = times(a, v);
  const double smallest = v.x * av.x + v.y * av.y + v.z * av.z;
  const double sum = 1.0 - smallest, product = c1 - smallest * sum, t4 = 4.0 * smallest;
  return (t4 < 0.5 * sum) & ((t4 - sum) * t4 + product > 0.0);
}

// Lane j's unit normal n into `out`, turned towards the scanner, with the
// cosine of its incidence angle.
inline void store_towards_scanner(const Vector3& n, const LaneCentres& c, int j, bool ok,
                                  LanePlanes& out) {
  const float nx = static_cast<float>(n.x), ny = static_cast<float>(n.y),
              nz = static_cast<float>(n.z);
  const float away = nx * c.x[j] + ny * c.y[j] + nz * c.z[j];  // > 0: faces away
  const float sign =
      select_bits(-1.0f, all_bits(away > 0.0f)) + select_bits(1.0f, all_bits(!(away > 0.0f)));
  out.x[j] = sign * nx, out.y[j] = sign * ny, out.z[j] = sign * nz;
  out.cos_incidence[j] = std::abs(nx * c.view_x[j] + ny * c.view_y[j] + nz * c.view_z[j]);
  out.ok[j] = ok;
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
    const NormalisedCovariance covariance = normalised_covariance(s, j);
    const Symmetric3& a = covariance.a;
    const double c1 = minor_sum(a);  // ≤ 0: rank ≤ 1, a line or a point
    const double sigma = determinant(a) / or_one(c1, c1 > 0.0);
    const UnitVector n = normalised(dominant_direction(shifted_adjugate(a, sigma)));
    const bool ok = covariance.ok & (c1 > 0.0) & n.ok & is_planar(a, c1, n.v);
    store_towards_scanner(n.v, c, j, ok, out);
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
void add_offset(const float* __restrict range_m, const float* __restrict log_range,
                const float* __restrict cos_az, const float* __restrict sin_az, float cos_el,
                float sin_el, float limit, const float* __restrict centre_log_range,
                const float* __restrict centre_x, const float* __restrict centre_y,
                const float* __restrict centre_z, LaneSums& __restrict s) {
  for (int j = 0; j < kCovarianceLanes; ++j) {
    const bool take = std::abs(log_range[j] - centre_log_range[j]) <= limit;
    const std::uint32_t keep = all_bits(take);
    const float px = select_bits(range_m[j] * (cos_el * cos_az[j]) - centre_x[j], keep);
    const float py = select_bits(range_m[j] * (cos_el * sin_az[j]) - centre_y[j], keep);
    const float pz = select_bits(range_m[j] * sin_el - centre_z[j], keep);
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

// Footprints and normals from pixel adjacency (seed 004 §4.2).
//
// Normals of spherical scans come from the gradient of log-range over the
// angles. With p = r·u(θ, φ) and the orthonormal frame (u, e_θ, e_φ),
//   ∂p/∂θ = r_θ u + r cos φ e_θ,   ∂p/∂φ = r_φ u + r e_φ,
//   ∂p/∂θ × ∂p/∂φ ∝ u − (∂ln r/∂θ) / cos φ · e_θ − (∂ln r/∂φ) · e_φ,
// so a normal needs only the two slopes of ln r, which a least-squares plane
// fit of ln r over the pixel window gives from ten running window moments
// (window_moments.hpp): constant time per pixel for any window size. That fit
// is exact to second order only in a full, symmetric window; windows cut by a
// depth discontinuity, by invalid pixels or by the grid's border get a
// covariance fit of their 3D points instead, leaving out the neighbours across
// the discontinuity. Scans with per-pixel directions have no angle model and
// always take the covariance fit.
#include "acquisition/scan_geometry.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <optional>

#include "acquisition/mixed_pixels.hpp"
#include "acquisition/parallel.hpp"
#include "acquisition/window_moments.hpp"

namespace scanbench::acquisition {
namespace {

template <typename Body>
void parallel_rows(int rows, int threads, Body&& body) {
  parallel_for_index(rows, threads, body, 8);
}

// Least-squares slopes (per column, per row) of v over a window, from its
// moments; false when the window does not span two independent directions.
bool plane_slopes(double n, double sx, double sy, double sxx, double sxy, double syy, double sv,
                  double sxv, double syv, double& b, double& c) {
  if (n < 3) return false;
  const double cxx = sxx - sx * sx / n, cxy = sxy - sx * sy / n, cyy = syy - sy * sy / n;
  const double cxv = sxv - sx * sv / n, cyv = syv - sy * sv / n;
  const double det = cxx * cyy - cxy * cxy;
  if (cxx < 0.5 || cyy < 0.5 || det < 0.25 * cxx * cyy) return false;
  b = (cyy * cxv - cxy * cyv) / det;
  c = (cxx * cyv - cxy * cxv) / det;
  return true;
}

// 1 where a masked pixel's log-range jumps: its second difference along the
// row or the column exceeds the threshold of GeometrySettings (noise-aware,
// capped by depth_jump_relative).
std::vector<std::uint8_t> jump_map(const Scan& scan, const std::vector<std::uint8_t>& mask,
                                   const std::vector<float>& v, const GeometrySettings& settings) {
  std::vector<std::uint8_t> jumps(mask.size(), 0);
  const int columns = scan.columns;
  const double noise_factor = settings.depth_jump_sigmas * std::sqrt(6.0);
  parallel_rows(scan.rows, settings.threads, [&](int r) {
    for (int c = 0; c < columns; ++c) {
      const std::size_t i = scan.index(r, c);
      if (!mask[i]) continue;
      const double range = scan.range_m[i];
      const double sigma = settings.range_noise_m + settings.range_noise_per_m * range;
      const double jump = std::min(settings.depth_jump_relative, noise_factor * sigma / range);
      const auto jumps_between = [&](std::size_t before, std::size_t after) {
        return mask[before] && mask[after] && std::abs(v[before] - 2 * v[i] + v[after]) > jump;
      };
      jumps[i] = (c > 0 && c + 1 < columns && jumps_between(i - 1, i + 1)) ||
                 (r > 0 && r + 1 < scan.rows && jumps_between(i - columns, i + columns));
    }
  });
  return jumps;
}

// Sines and cosines of every column's azimuth and every row's elevation, so
// the per-pixel work is free of trigonometry.
struct AngleTables {
  std::vector<double> cos_az, sin_az, cos_el, sin_el;

  explicit AngleTables(const Scan& scan) {
    const auto* a = std::get_if<SphericalAngles>(&scan.angles);
    if (a == nullptr) return;
    for (int col = 0; col < scan.columns; ++col) {
      const double az = a->azimuth_start_rad + col * a->azimuth_step_rad;
      cos_az.push_back(std::cos(az));
      sin_az.push_back(std::sin(az));
    }
    for (int row = 0; row < scan.rows; ++row) {
      const double el = a->elevation_start_rad + row * a->elevation_step_rad;
      cos_el.push_back(std::cos(el));
      sin_el.push_back(std::sin(el));
    }
  }

  // The pixel's unit viewing direction, from the tables when the scan is spherical.
  Eigen::Vector3f direction(const Scan& scan, int row, int col) const {
    if (cos_az.empty()) return acquisition::direction(scan, row, col);
    return Eigen::Vector3d(cos_el[row] * cos_az[col], cos_el[row] * sin_az[col], sin_el[row])
        .cast<float>();
  }
};

// The log-range slopes of the widest clean window of every pixel: widest
// first, a pixel takes the first window size at which its whole window is
// valid and free of depth discontinuities.
struct WindowSlopes {
  std::vector<float> per_column, per_row;  // d ln r / d col, d ln r / d row
  std::vector<std::uint16_t> used;         // window pixels; 0 = no clean window

  WindowSlopes(const Scan& scan, const std::vector<std::uint8_t>& mask,
               const std::vector<float>& log_range, const std::vector<std::uint8_t>& jump_map,
               const GeometrySettings& settings)
      : per_column(scan.pixel_count(), 0.0f),
        per_row(scan.pixel_count(), 0.0f),
        used(scan.pixel_count(), 0) {
    for (int radius = settings.window_radius;;) {
      add_scale(scan, radius, mask, log_range, jump_map, settings.threads);
      if (radius <= settings.edge_window_radius) break;
      radius =
          radius / 2 >= 2 * settings.edge_window_radius ? radius / 2 : settings.edge_window_radius;
    }
  }

 private:
  void add_scale(const Scan& scan, int radius, const std::vector<std::uint8_t>& mask,
                 const std::vector<float>& log_range, const std::vector<std::uint8_t>& jump_map,
                 int threads) {
    const std::vector<std::uint16_t> jumps =
        window_counts(scan.rows, scan.columns, radius, jump_map, threads);
    const float full = static_cast<float>((2 * radius + 1) * (2 * radius + 1));
    visit_window_moments(
        scan.rows, scan.columns, radius, mask, log_range, threads,
        [&](int row, int begin, int end, const WindowMoments* moments) {
          for (int col = begin; col < end; ++col) {
            const std::size_t i = scan.index(row, col);
            const WindowMoments& m = moments[col - begin];
            if (used[i] || !mask[i] || jumps[i] != 0 || m.n != full) continue;
            double b = 0, c = 0;
            if (!plane_slopes(m.n, m.sx, m.sy, m.sxx, m.sxy, m.syy, m.sv, m.sxv, m.syv, b, c))
              continue;
            per_column[i] = static_cast<float>(b);
            per_row[i] = static_cast<float>(c);
            used[i] = static_cast<std::uint16_t>(m.n);
          }
        });
  }
};

struct GridContext {
  const Scan& scan;
  const GeometrySettings& settings;
  const std::vector<std::uint8_t>& mask;  // valid and not mixed
  const std::vector<float>& log_range;
  const std::vector<Eigen::Vector3f>& points;  // scan frame, where masked
};

// Unit normal towards the scanner from the log-range slopes per column (b)
// and per row (c) at a pixel of a spherical scan.
Eigen::Vector3f spherical_normal(const SphericalAngles& a, const AngleTables& t, int row, int col,
                                 double b, double c) {
  const double ca = t.cos_az[col], sa = t.sin_az[col], ce = t.cos_el[row], se = t.sin_el[row];
  const Eigen::Vector3d u(ce * ca, ce * sa, se), e_az(-sa, ca, 0.0), e_el(-se * ca, -se * sa, ce);
  const double g_az = b / a.azimuth_step_rad / std::max(ce, 1e-3);
  const double g_el = c / a.elevation_step_rad;
  return (-u + g_az * e_az + g_el * e_el).normalized().cast<float>();
}

// Covariance fit of the 3D points over the window (per-pixel grids).
bool covariance_normal(const GridContext& g, int row, int col, Eigen::Vector3f& normal, int& used) {
  const int k = g.settings.edge_window_radius;
  const std::size_t centre_index = g.scan.index(row, col);
  const float centre = g.log_range[centre_index];
  const Eigen::Vector3f origin = g.points[centre_index];  // sums relative to it stay small
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  used = 0;
  for (int r = std::max(0, row - k); r <= std::min(g.scan.rows - 1, row + k); ++r) {
    for (int cc = std::max(0, col - k); cc <= std::min(g.scan.columns - 1, col + k); ++cc) {
      const std::size_t i = g.scan.index(r, cc);
      const float limit = static_cast<float>(g.settings.depth_jump_relative) *
                          static_cast<float>(std::max(std::abs(r - row), std::abs(cc - col)));
      if (!g.mask[i] || std::abs(g.log_range[i] - centre) > limit + 1e-7f) continue;
      const Eigen::Vector3f p = g.points[i] - origin;
      sum += p;
      xx += p.x() * p.x(), xy += p.x() * p.y(), xz += p.x() * p.z();
      yy += p.y() * p.y(), yz += p.y() * p.z(), zz += p.z() * p.z();
      ++used;
    }
  }
  if (used < 3) return false;
  const Eigen::Vector3f mean = sum / static_cast<float>(used);
  Eigen::Matrix3f covariance;
  covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  covariance = covariance / static_cast<float>(used) - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3f& values = solver.eigenvalues();
  if (values[1] <= 4.0f * values[0]) return false;  // a line or a blob, not a surface
  normal = solver.eigenvectors().col(0).normalized();
  if (normal.dot(origin) > 0) normal = -normal;
  return true;
}

float footprint(const Scan& scan, const AngleTables& tables, int row, int col,
                const Eigen::Vector3f& normal, const GeometrySettings& settings) {
  const std::size_t i = scan.index(row, col);
  double spacing_az = 0, spacing_el = 0;
  if (const auto* a = std::get_if<SphericalAngles>(&scan.angles)) {
    spacing_az = std::abs(a->azimuth_step_rad) * tables.cos_el[row];
    spacing_el = std::abs(a->elevation_step_rad);
  } else {  // angle to the next column and row of the direction grid
    const Eigen::Vector3f d = direction(scan, row, col);
    const int c2 = col + 1 < scan.columns ? col + 1 : col - 1,
              r2 = row + 1 < scan.rows ? row + 1 : row - 1;
    if (c2 >= 0) spacing_az = std::acos(std::clamp(d.dot(direction(scan, row, c2)), -1.0f, 1.0f));
    if (r2 >= 0) spacing_el = std::acos(std::clamp(d.dot(direction(scan, r2, col)), -1.0f, 1.0f));
  }
  const double gap = scan.range_m[i] * std::sqrt(spacing_az * spacing_az + spacing_el * spacing_el);
  double cos_incidence = 1.0;
  if (normal != Eigen::Vector3f::Zero())
    cos_incidence = std::abs(normal.dot(tables.direction(scan, row, col)));
  return static_cast<float>(0.5 * gap /
                            std::max(cos_incidence, 1.0 / settings.max_footprint_stretch));
}

}  // namespace

namespace {

// The per-pixel inputs every fit reads: which pixels take part (valid, not
// mixed), their log-range and their scan-frame points.
struct FitInputs {
  std::vector<std::uint8_t> mixed, mask, jumps;
  std::vector<float> log_range;
  std::vector<Eigen::Vector3f> points;
};

FitInputs prepare_inputs(const Scan& scan, const AngleTables& tables,
                         const GeometrySettings& settings) {
  const std::size_t n = scan.pixel_count();
  FitInputs in;
  in.mixed = settings.flag_mixed_pixels ? detect_mixed_pixels(scan, settings)
                                        : std::vector<std::uint8_t>(n, 0);
  in.mask.assign(n, 0);
  in.log_range.assign(n, 0.0f);
  in.points.assign(n, Eigen::Vector3f::Zero());
  parallel_rows(scan.rows, settings.threads, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      in.mask[i] = scan.valid[i] && !in.mixed[i] && scan.range_m[i] > 0.0f;
      if (!in.mask[i]) continue;
      in.log_range[i] = std::log(scan.range_m[i]);
      in.points[i] = scan.range_m[i] * tables.direction(scan, row, col);
    }
  });
  in.jumps = jump_map(scan, in.mask, in.log_range, settings);
  return in;
}

// Normal, confidence, flags and footprint of one valid pixel.
void fit_pixel(const GridContext& context, const AngleTables& tables, const FitInputs& in,
               const WindowSlopes* slopes, int row, int col, ScanGeometry& g) {
  const Scan& scan = context.scan;
  const GeometrySettings& settings = context.settings;
  const std::size_t i = scan.index(row, col);
  std::uint8_t flags = (in.mixed[i] ? kFlagMixedPixel : 0) | (in.jumps[i] ? kFlagEdge : 0);
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  int used = 0;
  bool ok = false;
  double area = (2.0 * settings.edge_window_radius + 1) * (2.0 * settings.edge_window_radius + 1);
  if (in.mask[i] && slopes != nullptr && slopes->used[i] > 0) {
    used = slopes->used[i];
    area = used;
    normal = spherical_normal(std::get<SphericalAngles>(scan.angles), tables, row, col,
                              slopes->per_column[i], slopes->per_row[i]);
    ok = true;
  } else if (in.mask[i]) {
    // No clean window (cut by a discontinuity, an invalid region or the
    // grid's border), or no angle model: the log-range slope of a lopsided
    // window is biased by the curvature of ln r, a 3D plane fit is not.
    ok = covariance_normal(context, row, col, normal, used);
  }
  ok = ok && used >= settings.min_neighbours && normal.allFinite();
  if (ok) {
    const float cos_incidence = std::abs(normal.dot(tables.direction(scan, row, col)));
    g.normal[i] = normal;
    g.confidence[i] =
        std::max(1e-6f, static_cast<float>(std::min(1.0, used / area)) * cos_incidence);
  } else {
    flags |= kFlagNoNormal;
  }
  g.flags[i] = flags;
  g.footprint_m[i] = footprint(scan, tables, row, col, g.normal[i], settings);
}

void count_results(const Scan& scan, GeometryResult& result) {
  const ScanGeometry& g = result.geometry;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    if (!scan.valid[i]) continue;
    ++result.valid_points;
    result.normals += g.has_normal(i);
    result.mixed_pixels += (g.flags[i] & kFlagMixedPixel) != 0;
    result.edge_pixels += (g.flags[i] & kFlagEdge) != 0;
  }
}

}  // namespace

GeometryResult compute_geometry(const Scan& scan, const GeometrySettings& settings) {
  assert(check_consistency(scan).empty() && settings.edge_window_radius >= 1 &&
         settings.window_radius >= settings.edge_window_radius &&
         settings.window_radius <= kMaxWindowRadius);
  const auto start = std::chrono::steady_clock::now();
  const AngleTables tables(scan);
  const FitInputs in = prepare_inputs(scan, tables, settings);
  std::optional<WindowSlopes> slopes;
  if (scan.is_spherical()) slopes.emplace(scan, in.mask, in.log_range, in.jumps, settings);
  const GridContext context{scan, settings, in.mask, in.log_range, in.points};

  GeometryResult result;
  ScanGeometry& g = result.geometry;
  const std::size_t n = scan.pixel_count();
  g.footprint_m.assign(n, 0.0f);
  g.normal.assign(n, Eigen::Vector3f::Zero());
  g.confidence.assign(n, 0.0f);
  g.flags.assign(n, 0);
  parallel_rows(scan.rows, settings.threads, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      if (scan.valid[scan.index(row, col)]) {
        fit_pixel(context, tables, in, slopes ? &*slopes : nullptr, row, col, g);
      }
    }
  });
  count_results(scan, result);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scanbench::acquisition

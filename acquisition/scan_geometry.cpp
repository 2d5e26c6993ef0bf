// Footprints and normals from pixel adjacency (seed 004 §4.2).
//
// Normals of spherical scans come from the gradient of log-range over the
// angles. With p = r·u(θ, φ) and the orthonormal frame (u, e_θ, e_φ),
//   ∂p/∂θ = r_θ u + r cos φ e_θ,   ∂p/∂φ = r_φ u + r e_φ,
//   ∂p/∂θ × ∂p/∂φ ∝ u − (∂ln r/∂θ) / cos φ · e_θ − (∂ln r/∂φ) · e_φ,
// so a normal needs only the two slopes of ln r, which a least-squares plane
// fit of ln r over the pixel window gives from integral images of its moments
// (window_moments.hpp): constant time per pixel for any window size. That fit
// is exact to second order only in a full, symmetric window; windows cut by a
// depth discontinuity, by invalid pixels or by the grid's border get a
// covariance fit of their 3D points instead (grid_covariance.hpp), leaving
// out the neighbours across the discontinuity. Scans with per-pixel
// directions have no angle model and always take the covariance fit.
//
// The stage runs as three passes over the grid, each parallel and each
// touching a pixel's data once: mixed pixels; mask, log-range and depth
// jumps; then tile by tile the window slopes, normals, confidences and
// footprints, so a tile's data is still in cache when its pixels finish.
#include "acquisition/scan_geometry.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <chrono>
#include <cmath>
#include <memory>

#include "acquisition/grid_covariance.hpp"
#include "acquisition/mixed_pixels.hpp"
#include "acquisition/parallel.hpp"
#include "acquisition/window_moments.hpp"

namespace scanbench::acquisition {
namespace {

template <typename Body>
void parallel_rows(int rows, int threads, Body&& body) {
  parallel_for_index(rows, threads, body, 8);
}

// What every fit reads per pixel. Scratch arrays are left uninitialised
// (make_unique_for_overwrite) and first written by the parallel passes, so
// their pages are faulted in by the threads that use them.
struct FitInputs {
  std::unique_ptr<std::uint8_t[]> mask;   // valid, not mixed, positive range
  std::unique_ptr<std::uint8_t[]> clean;  // masked and no depth jump
  std::unique_ptr<float[]> log_range;     // ln range where masked, else 0
};

// mask, log_range and the mixed-pixel flag of every pixel.
void mark_mixed_and_mask(const Scan& scan, const GeometrySettings& settings, FitInputs& in,
                         std::vector<std::uint8_t>& flags) {
  const std::vector<std::uint8_t> mixed = settings.flag_mixed_pixels
                                              ? detect_mixed_pixels(scan, settings)
                                              : std::vector<std::uint8_t>(scan.pixel_count(), 0);
  parallel_rows(scan.rows, settings.threads, [&](int row) {
    const std::size_t begin = scan.index(row, 0), end = begin + scan.columns;
    for (std::size_t i = begin; i < end; ++i) {
      flags[i] = mixed[i] ? kFlagMixedPixel : 0;
      const bool mask = scan.valid[i] && !mixed[i] && scan.range_m[i] > 0.0f;
      in.mask[i] = mask;
      in.log_range[i] = mask ? std::log(scan.range_m[i]) : 0.0f;
    }
  });
}

// clean and the edge flag: a masked pixel whose log-range jumps, i.e. its
// second difference along the row or the column exceeds the threshold of
// GeometrySettings (noise-aware, capped by depth_jump_relative).
void mark_jumps(const Scan& scan, const GeometrySettings& settings, FitInputs& in,
                std::vector<std::uint8_t>& flags) {
  const int columns = scan.columns;
  const double noise_factor = settings.depth_jump_sigmas * std::sqrt(6.0);
  const std::uint8_t* mask = in.mask.get();
  const float* v = in.log_range.get();
  parallel_rows(scan.rows, settings.threads, [&](int r) {
    for (int c = 0; c < columns; ++c) {
      const std::size_t i = scan.index(r, c);
      in.clean[i] = 0;
      if (!mask[i]) continue;
      const double range = scan.range_m[i];
      const double sigma = settings.range_noise_m + settings.range_noise_per_m * range;
      const double jump = std::min(settings.depth_jump_relative, noise_factor * sigma / range);
      const auto jumps_between = [&](std::size_t before, std::size_t after) {
        return mask[before] && mask[after] && std::abs(v[before] - 2 * v[i] + v[after]) > jump;
      };
      const bool jumps = (c > 0 && c + 1 < columns && jumps_between(i - 1, i + 1)) ||
                         (r > 0 && r + 1 < scan.rows && jumps_between(i - columns, i + columns));
      in.clean[i] = !jumps;
      flags[i] |= jumps ? kFlagEdge : 0;
    }
  });
}

FitInputs prepare_inputs(const Scan& scan, const GeometrySettings& settings,
                         std::vector<std::uint8_t>& flags) {
  const std::size_t n = scan.pixel_count();
  FitInputs in{std::make_unique_for_overwrite<std::uint8_t[]>(n),
               std::make_unique_for_overwrite<std::uint8_t[]>(n),
               std::make_unique_for_overwrite<float[]>(n)};
  mark_mixed_and_mask(scan, settings, in, flags);
  mark_jumps(scan, settings, in, flags);
  return in;
}

// Per-row factors of a spherical scan, so the per-pixel work is free of
// trigonometry and division.
struct RowFactors {
  std::vector<float> azimuth_gradient;  // 1 / (Δaz · cos el): d ln r / d col → ∂ ln r/∂az / cos el
  std::vector<float> half_spacing;  // half the pixel cell's diagonal per metre of range
  float elevation_gradient = 0.0f;  // 1 / Δel

  explicit RowFactors(const Scan& scan) {
    const auto* a = std::get_if<SphericalAngles>(&scan.angles);
    if (a == nullptr) return;
    for (int row = 0; row < scan.rows; ++row) {
      const double cos_el = std::cos(a->elevation_start_rad + row * a->elevation_step_rad);
      azimuth_gradient.push_back(
          static_cast<float>(1.0 / a->azimuth_step_rad / std::max(cos_el, 1e-3)));
      const double az = std::abs(a->azimuth_step_rad) * cos_el, el = a->elevation_step_rad;
      half_spacing.push_back(static_cast<float>(0.5 * std::sqrt(az * az + el * el)));
    }
    elevation_gradient = static_cast<float>(1.0 / a->elevation_step_rad);
  }
};

// Half the pixel cell's diagonal per metre of range on a per-pixel direction
// grid: the angles to the next column and row.
float half_spacing_per_pixel(const Scan& scan, int row, int col) {
  const Eigen::Vector3f d = direction(scan, row, col);
  const int c2 = col + 1 < scan.columns ? col + 1 : col - 1,
            r2 = row + 1 < scan.rows ? row + 1 : row - 1;
  double az = 0, el = 0;
  if (c2 >= 0) az = std::acos(std::clamp(d.dot(direction(scan, row, c2)), -1.0f, 1.0f));
  if (r2 >= 0) el = std::acos(std::clamp(d.dot(direction(scan, r2, col)), -1.0f, 1.0f));
  return static_cast<float>(0.5 * std::sqrt(az * az + el * el));
}

// Unit normal towards the scanner from the log-range slopes of a clean
// window. The frame (u, e_az, e_el) is orthonormal, so the unnormalised
// normal −u + g_az·e_az + g_el·e_el has length √(1 + g_az² + g_el²), and the
// cosine of the incidence angle is one over it.
NormalFit window_fit(const GridDirections& d, const RowFactors& f, const WindowSlope& s, int row,
                     int col) {
  const float ca = d.cos_az[col], sa = d.sin_az[col], ce = d.cos_el[row], se = d.sin_el[row];
  const float g_az = s.per_column * f.azimuth_gradient[row];
  const float g_el = s.per_row * f.elevation_gradient;
  const float inverse_length = 1.0f / std::sqrt(1.0f + g_az * g_az + g_el * g_el);
  const Eigen::Vector3f u(ce * ca, ce * sa, se), e_az(-sa, ca, 0.0f), e_el(-se * ca, -se * sa, ce);
  NormalFit fit;
  fit.normal = (-u + g_az * e_az + g_el * e_el) * inverse_length;
  fit.cos_incidence = inverse_length;
  fit.used = s.used;
  fit.window = s.used;
  fit.ok = true;
  return fit;
}

struct Counts {
  std::atomic<std::size_t> valid{0}, normals{0}, mixed{0}, edges{0};
};

struct StageContext {
  const Scan& scan;
  const GeometrySettings& settings;
  const FitInputs& in;
  const GridDirections& directions;
  const RowFactors& factors;
  ScanGeometry& g;
  Counts& counts;
};

// Normal, confidence, footprint and the no-normal flag of valid pixel i.
void store_pixel(const StageContext& c, const NormalFit& fit, std::size_t i, float half_spacing) {
  const bool ok = fit.ok && fit.used >= c.settings.min_neighbours && fit.normal.allFinite();
  float cos_incidence = 1.0f;
  if (ok) {
    cos_incidence = fit.cos_incidence;
    c.g.normal[i] = fit.normal;
    c.g.confidence[i] =
        std::max(1e-6f, std::min(1.0f, static_cast<float>(fit.used) / fit.window) * cos_incidence);
  } else {
    c.g.normal[i] = Eigen::Vector3f::Zero();
    c.g.flags[i] |= kFlagNoNormal;
  }
  const float stretch = static_cast<float>(1.0 / c.settings.max_footprint_stretch);
  c.g.footprint_m[i] = c.scan.range_m[i] * half_spacing / std::max(cos_incidence, stretch);
}

// Finishes pixels (row, begin … end − 1); `slopes` (spherical scans) holds
// their window fits, else every masked pixel takes the covariance fit.
void finish_pixels(const StageContext& c, int row, int begin, int end, const WindowSlope* slopes) {
  std::size_t valid = 0, normals = 0, mixed = 0, edges = 0;
  for (int col = begin; col < end; ++col) {
    const std::size_t i = c.scan.index(row, col);
    if (!c.scan.valid[i]) {
      c.g.normal[i] = Eigen::Vector3f::Zero();
      continue;
    }
    NormalFit fit;
    if (slopes != nullptr && slopes[col - begin].used > 0) {
      fit = window_fit(c.directions, c.factors, slopes[col - begin], row, col);
    } else if (c.in.mask[i]) {
      // No clean window (cut by a discontinuity, an invalid region or the
      // grid's border), or no angle model: the log-range slope of a lopsided
      // window is biased by the curvature of ln r, a 3D plane fit is not.
      fit = covariance_fit(c.directions, c.scan.range_m.data(), c.in.mask.get(),
                           c.in.log_range.get(), row, col, c.scan.rows, c.settings);
    }
    store_pixel(
        c, fit, i,
        slopes != nullptr ? c.factors.half_spacing[row] : half_spacing_per_pixel(c.scan, row, col));
    ++valid;
    normals += c.g.confidence[i] > 0.0f;
    mixed += (c.g.flags[i] & kFlagMixedPixel) != 0;
    edges += (c.g.flags[i] & kFlagEdge) != 0;
  }
  c.counts.valid += valid, c.counts.normals += normals;
  c.counts.mixed += mixed, c.counts.edges += edges;
}

// The window radii of the cascade, widest first: halving from window_radius
// down to edge_window_radius.
std::vector<int> cascade_radii(const GeometrySettings& settings) {
  std::vector<int> radii;
  for (int radius = settings.window_radius;;) {
    radii.push_back(radius);
    if (radius <= settings.edge_window_radius) break;
    radius =
        radius / 2 >= 2 * settings.edge_window_radius ? radius / 2 : settings.edge_window_radius;
  }
  return radii;
}

void allocate(ScanGeometry& g, std::size_t n) {
  g.footprint_m.assign(n, 0.0f);
  g.normal.resize(n);  // Eigen leaves it uninitialised; every pixel is written below
  g.confidence.assign(n, 0.0f);
  g.flags.assign(n, 0);
}

}  // namespace

GeometryResult compute_geometry(const Scan& scan, const GeometrySettings& settings) {
  assert(check_consistency(scan).empty() && settings.edge_window_radius >= 1 &&
         settings.window_radius >= settings.edge_window_radius &&
         settings.window_radius <= kMaxWindowRadius);
  const auto start = std::chrono::steady_clock::now();
  GeometryResult result;
  ScanGeometry& g = result.geometry;
  allocate(g, scan.pixel_count());
  const FitInputs in = prepare_inputs(scan, settings, g.flags);
  const GridDirections directions(scan);
  const RowFactors factors(scan);
  Counts counts;
  const StageContext context{scan, settings, in, directions, factors, g, counts};
  if (scan.is_spherical()) {
    const std::vector<int> radii = cascade_radii(settings);
    visit_window_slopes(scan.rows, scan.columns, radii, {in.clean.get(), scan.pixel_count()},
                        {in.log_range.get(), scan.pixel_count()}, settings.threads,
                        [&](int row, int begin, int end, const WindowSlope* slopes) {
                          finish_pixels(context, row, begin, end, slopes);
                        });
  } else {
    parallel_rows(scan.rows, settings.threads,
                  [&](int row) { finish_pixels(context, row, 0, scan.columns, nullptr); });
  }
  result.valid_points = counts.valid, result.normals = counts.normals;
  result.mixed_pixels = counts.mixed, result.edge_pixels = counts.edges;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scanbench::acquisition

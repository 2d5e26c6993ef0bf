// Footprints and normals from pixel adjacency (seed 004 §4.2).
//
// Normals of spherical scans come from the inverse range w = 1/r over the
// angles. A plane n·p = 1 seen along the unit beam u(θ, φ) (azimuth θ,
// elevation φ) has w = n·u = cos φ (n_x cos θ + n_y sin θ) + n_z sin φ: a
// sinusoid of each angle. So the window sums of w, dx·w and dy·w over a full,
// symmetric pixel window are those of the plane's three components at the
// centre, each scaled by a sum of cosines or sines of the window's angle
// offsets that depends on the window size and the angle steps alone (see
// window_normals): the plane comes back, at any incidence, from the three
// moments a least-squares fit over the window
// gives from integral images (window_moments.hpp), in constant time per
// pixel. (The slopes of ln r that an earlier version fitted are exact to
// second order only: their third-order term cost a few hundredths of a
// degree at grazing incidence, more than a phase-shift scanner's noise.)
// Windows cut by a depth discontinuity, by invalid pixels or by the grid's
// border get a covariance fit of their 3D points instead
// (grid_covariance.hpp), leaving out the neighbours across the
// discontinuity. Scans with per-pixel directions have no angle model and
// always take the covariance fit.
//
// The stage runs as three passes over the grid, each parallel and each
// touching a pixel's data once: mixed pixels; mask, log-range, inverse
// range and depth jumps; then tile by tile the window slopes, normals, confidences and
// footprints, so a tile's data is still in cache when its pixels finish.
#include "acquisition/geometry/scan_geometry.hpp"

#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "acquisition/geometry/branch_free.hpp"
#include "acquisition/geometry/grid_covariance.hpp"
#include "acquisition/geometry/grid_geometry.hpp"
#include "acquisition/geometry/mixed_pixels.hpp"
#include "acquisition/geometry/window_moments.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "core/timing.hpp"

namespace scanbench::acquisition {
namespace {

template <typename Body>
void parallel_rows(int rows, int threads, Body&& body) {
  core::parallel_for_index(rows, threads, body, 8);
}

// What every fit reads per pixel. Scratch arrays are left uninitialised
// (make_unique_for_overwrite) and first written by the parallel passes, so
// their pages are faulted in by the threads that use them.
struct FitInputs {
  std::unique_ptr<std::uint8_t[]> mixed;  // 1 = mixed pixel
  // Valid with a positive finite range. Mixed pixels stay in the depth-jump
  // test and the window fits: the jump test keeps the windows off the edges
  // that blend, and a pixel flagged where there is none (a noise excursion
  // under a noisy sensor) would otherwise cut every wide window around it.
  std::unique_ptr<std::uint8_t[]> mask;
  std::unique_ptr<std::uint8_t[]> clean;  // masked and no depth jump
  std::unique_ptr<float[]> log_range;     // ln range where masked, else NaN
  std::unique_ptr<float[]> inverse_range;  // 1 / range where masked, else 0
  // log_range, NaN also where mixed: the covariance fallback, which picks
  // neighbours by their log-range alone, leaves blends out.
  std::unique_ptr<float[]> fallback_log_range;

  explicit FitInputs(std::size_t n)
      : mixed(std::make_unique_for_overwrite<std::uint8_t[]>(n)),
        mask(std::make_unique_for_overwrite<std::uint8_t[]>(n)),
        clean(std::make_unique_for_overwrite<std::uint8_t[]>(n)),
        log_range(std::make_unique_for_overwrite<float[]>(n)),
        inverse_range(std::make_unique_for_overwrite<float[]>(n)),
        fallback_log_range(std::make_unique_for_overwrite<float[]>(n)) {}

  // The mixed-pixel and edge flags of pixel i (an edge: masked, not clean).
  std::uint8_t flags(std::size_t i) const {
    return static_cast<std::uint8_t>((mixed[i] ? kFlagMixedPixel : 0) |
                                     (mask[i] && !clean[i] ? kFlagEdge : 0));
  }
};

// mask, log_range, inverse_range and fallback_log_range of n pixels of a
// row. Branch-free over plain, unaliased arrays, so that it vectorizes. A
// range that is not a positive normal float (or is infinite) is no return
// here.
SCANBENCH_VECTOR_CLONES void mask_row(int n, const std::uint8_t* __restrict valid,
                                      const std::uint8_t* __restrict mixed,
                                      const float* __restrict range_m,
                                      std::uint8_t* __restrict mask, float* __restrict log_range,
                                      float* __restrict inverse_range,
                                      float* __restrict fallback_log_range) {
  constexpr std::uint32_t kNaN = 0x7fc00000u;
  for (int i = 0; i < n; ++i) {
    const bool masked = (valid[i] != 0) & (range_m[i] >= std::numeric_limits<float>::min()) &
                        (range_m[i] <= std::numeric_limits<float>::max());
    const std::uint32_t keep = all_bits(masked);
    mask[i] = masked;
    log_range[i] = std::bit_cast<float>(
        (std::bit_cast<std::uint32_t>(log_positive(range_m[i])) & keep) | (kNaN & ~keep));
    const float divisor = select_bits(range_m[i], keep) + select_bits(1.0f, ~keep);
    inverse_range[i] = select_bits(1.0f / divisor, keep);
    const std::uint32_t fits = keep & all_bits(mixed[i] == 0);
    fallback_log_range[i] =
        std::bit_cast<float>((std::bit_cast<std::uint32_t>(log_range[i]) & fits) | (kNaN & ~fits));
  }
}

// mixed, mask, log_range, inverse_range and fallback_log_range of every pixel.
void mark_mixed_and_mask(const Scan& scan, const GeometrySettings& settings, FitInputs& in) {
  const std::span<std::uint8_t> mixed(in.mixed.get(), scan.pixel_count());
  if (settings.flag_mixed_pixels) detect_mixed_pixels(scan, settings, mixed);
  parallel_rows(scan.rows, settings.threads, [&](int row) {
    const std::size_t i = scan.index(row, 0);
    if (!settings.flag_mixed_pixels) std::fill(&mixed[i], &mixed[i] + scan.columns, 0);
    mask_row(scan.columns, scan.valid.data() + i, &mixed[i], scan.range_m.data() + i,
             in.mask.get() + i, in.log_range.get() + i, in.inverse_range.get() + i,
             in.fallback_log_range.get() + i);
  });
}

// The depth-jump test of GeometrySettings: a second difference `d` of
// log-range above depth_jump_sigmas · √6 · σ(range) / range, or above
// depth_jump_relative where that is also above 5/6 of the former (5 σ at
// the default 6): the relative test catches small edges near the scanner,
// but never inside the noise, which a noisy sensor (a structured-light
// camera at 5 m: σ / range = 0.75 %) would otherwise turn into jumps all
// over its surfaces. Compared as d · range > √6 · sigmas · σ, without a
// division.
struct JumpTest {
  float relative;  // threshold on d (ln range: no unit)
  // threshold · range [m] = noise0_m + (noise1 + noise2 · range) · range [m]
  float noise0_m, noise1, noise2;

  explicit JumpTest(const GeometrySettings& s)
      : relative(static_cast<float>(s.depth_jump_relative)),
        noise0_m(static_cast<float>(s.depth_jump_sigmas * std::sqrt(6.0) * s.range_noise.noise_m)),
        noise1(
            static_cast<float>(s.depth_jump_sigmas * std::sqrt(6.0) * s.range_noise.noise_per_m)),
        noise2(
            static_cast<float>(s.depth_jump_sigmas * std::sqrt(6.0) * s.range_noise.noise_per_m2)) {
  }

  bool operator()(float before, float centre, float after, float range_m) const {
    const float d = std::abs(before - 2.0f * centre + after);
    const float noise = noise0_m + (noise1 + noise2 * range_m) * range_m;
    constexpr float kFloor = 5.0f / 6.0f;
    return (d * range_m > noise) | ((d > relative) & (d * range_m > kFloor * noise));
  }
};

// Interior pixels 1 … n − 2 of a row whose rows above and below exist;
// branch-free over plain, unaliased arrays so that the loop vectorizes.
SCANBENCH_VECTOR_CLONES void interior_jumps(int n, std::ptrdiff_t stride, const JumpTest& test,
                                            const std::uint8_t* __restrict mask,
                                            const float* __restrict v,
                                            const float* __restrict range_m,
                                            std::uint8_t* __restrict clean) {
  for (int c = 1; c + 1 < n; ++c) {
    const bool along_row =
        (mask[c - 1] != 0) & (mask[c + 1] != 0) & test(v[c - 1], v[c], v[c + 1], range_m[c]);
    const bool along_column = (mask[c - stride] != 0) & (mask[c + stride] != 0) &
                              test(v[c - stride], v[c], v[c + stride], range_m[c]);
    const bool jumps = (mask[c] != 0) & (along_row | along_column);
    clean[c] = (mask[c] != 0) & !jumps;
  }
}

// clean (masked and no depth jump) for every pixel.
void mark_jumps(const Scan& scan, const GeometrySettings& settings, FitInputs& in) {
  const JumpTest test(settings);
  const int rows = scan.rows, columns = scan.columns;
  const std::uint8_t* mask = in.mask.get();
  const float* v = in.log_range.get();
  const auto one_pixel = [&](int r, int c) {
    const std::size_t i = scan.index(r, c);
    const auto jumps_between = [&](std::size_t before, std::size_t after) {
      return mask[before] && mask[after] && test(v[before], v[i], v[after], scan.range_m[i]);
    };
    const bool jumps =
        mask[i] && ((c > 0 && c + 1 < columns && jumps_between(i - 1, i + 1)) ||
                    (r > 0 && r + 1 < rows && jumps_between(i - columns, i + columns)));
    in.clean[i] = mask[i] && !jumps;
  };
  parallel_rows(rows, settings.threads, [&](int r) {
    const std::size_t i = scan.index(r, 0);
    if (r == 0 || r + 1 == rows || columns < 3) {
      for (int c = 0; c < columns; ++c) one_pixel(r, c);
      return;
    }
    one_pixel(r, 0);
    interior_jumps(columns, columns, test, mask + i, v + i, scan.range_m.data() + i,
                   in.clean.get() + i);
    one_pixel(r, columns - 1);
  });
}

// Per-row factors of a spherical scan, so the per-pixel work is free of
// trigonometry and division.
struct RowFactors {
  std::vector<float> azimuth_gradient;  // 1 / (Δaz · cos el): d w / d col → ∂w/∂az / cos el
  // Half the pixel cell's diagonal [rad]: the footprint [m] per metre of range.
  std::vector<float> half_spacing_rad;
  float elevation_gradient = 0.0f;  // 1 / Δel
  float azimuth_step_sq = 0.0f, elevation_step_sq = 0.0f;  // Δaz², Δel² [rad²]

  // `first_row` as for GridDirections.
  RowFactors(const Scan& scan, int first_row) {
    const auto* a = std::get_if<SphericalAngles>(&scan.angles);
    if (a == nullptr) return;
    for (int row = 0; row < scan.rows; ++row) {
      const double cos_el = std::cos(a->elevation(first_row + row));
      azimuth_gradient.push_back(
          static_cast<float>(1.0 / a->azimuth_step_rad / std::max(cos_el, 1e-3)));
      const double az = std::abs(a->azimuth_step_rad) * cos_el, el = a->elevation_step_rad;
      half_spacing_rad.push_back(static_cast<float>(0.5 * std::sqrt(az * az + el * el)));
    }
    elevation_gradient = static_cast<float>(1.0 / a->elevation_step_rad);
    azimuth_step_sq = static_cast<float>(a->azimuth_step_rad * a->azimuth_step_rad);
    elevation_step_sq = static_cast<float>(a->elevation_step_rad * a->elevation_step_rad);
  }
};

// Half the pixel cell's diagonal [rad] on a per-pixel direction grid, from
// the angles to the next column and row.
float per_pixel_half_spacing_rad(const Scan& scan, int row, int col) {
  const Eigen::Vector3f d = direction(scan, row, col);
  const int c2 = col + 1 < scan.columns ? col + 1 : col - 1,
            r2 = row + 1 < scan.rows ? row + 1 : row - 1;
  double az = 0, el = 0;
  if (c2 >= 0) az = std::acos(std::clamp(d.dot(direction(scan, row, c2)), -1.0f, 1.0f));
  if (r2 >= 0) el = std::acos(std::clamp(d.dot(direction(scan, r2, col)), -1.0f, 1.0f));
  return static_cast<float>(0.5 * std::sqrt(az * az + el * el));
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

// Normal, confidence, footprint and the no-normal flag of valid pixel i
// from a covariance fit (or from none: fit.ok false).
void store_fit(const StageContext& c, const NormalFit& fit, std::size_t i, float half_spacing_rad) {
  const bool ok = fit.ok && fit.used >= c.settings.min_neighbours && fit.normal.allFinite();
  float cos_incidence = 1.0f;
  if (ok) {
    cos_incidence = fit.cos_incidence;
    c.g.normal[i] = fit.normal;
    c.g.confidence[i] =
        std::max(1e-6f, std::min(1.0f, static_cast<float>(fit.used) / fit.window) * cos_incidence);
  } else {
    c.g.normal[i] = Eigen::Vector3f::Zero();
    c.g.confidence[i] = 0.0f;
    c.g.flags[i] |= kFlagNoNormal;
  }
  const float stretch = static_cast<float>(1.0 / c.settings.max_footprint_stretch);
  c.g.footprint_m[i] = c.scan.range_m[i] * half_spacing_rad / std::max(cos_incidence, stretch);
}

// Adds the counts of GeometryResult for pixels [first, first + count).
void count_pixels(const StageContext& c, std::size_t first, int count) {
  std::size_t valid = 0, normals = 0, mixed = 0, edges = 0;
  for (std::size_t i = first; i < first + count; ++i) {
    valid += c.scan.valid[i] != 0;
    normals += c.g.confidence[i] > 0.0f;
    mixed += (c.g.flags[i] & kFlagMixedPixel) != 0;
    edges += (c.g.flags[i] & kFlagEdge) != 0;
  }
  c.counts.valid += valid, c.counts.normals += normals;
  c.counts.mixed += mixed, c.counts.edges += edges;
}

// What the window normals of one row share.
struct RowConstants {
  float cos_el, sin_el;
  float az_gradient, el_gradient;  // slope per pixel → per radian (see RowFactors)
  float az_step_sq, el_step_sq;    // see RowFactors
  float half_spacing_rad;          // see RowFactors
  float max_stretch;
  std::uint16_t min_used;  // pixels a window fit needs
};

// The per-pixel arrays of a row segment that window_normals reads, n entries
// each, and those it writes. No output overlaps another array: the
// __restrict members say so, which GCC uses for a struct passed by value.
struct WindowNormalInputs {
  // The window fits of the inverse range (WindowSlopeRow).
  const float* __restrict mean;
  const float* __restrict per_column;
  const float* __restrict per_row;
  const std::uint16_t* __restrict used;
  // The pixels' azimuths (GridDirections).
  const float* __restrict cos_az;
  const float* __restrict sin_az;
  // The scan's, then FitInputs'.
  const float* __restrict range_m;
  const std::uint8_t* __restrict valid;
  const std::uint8_t* __restrict mask;
  const std::uint8_t* __restrict mixed;
  const std::uint8_t* __restrict clean;
};

struct WindowNormalOutputs {
  float* __restrict nx;  // the unit normal's components
  float* __restrict ny;
  float* __restrict nz;
  float* __restrict confidence;
  float* __restrict footprint_m;
  std::uint8_t* __restrict flags;
};

// The normal of one pixel's window fit of the inverse range. About the
// window's centre (azimuth θ0, elevation φ0) a plane n·p = 1 has
//   w = cos φ (A cos dθ + B sin dθ) + E sin φ,
// with A, B its components along the beam's horizontal direction and across
// it, E the vertical one. Over a full window of radius k, steps hθ and hφ:
//   Σ w      = Cφ (A Cθ cos φ0 + E N sin φ0),
//   Σ dy·w   = Sφ (−A Cθ sin φ0 + E N cos φ0),
//   Σ dx·w   = Cφ cos φ0 · B Sθ,
// where N = 2k + 1, C = Σ cos(d·h) and S = Σ d·sin(d·h) over d in [−k, k].
// The least-squares fit divides them by N², N·Σd² and N·Σd², so relative to
// its plain values, with K = k(k + 1) = (N² − 1)/4, to second order in
// h²K (the rest is about h⁴K²/120: 2·10⁻⁷ for k = 16 at 0.25° steps, 1 %
// for k = 127 at 0.5°):
//   C / N = 1 − h²K/6,   S / (h Σd²) = 1 − h²(3K − 1)/30.
// Solving the rotation by φ0 gives A and E, the column slope gives B; n
// points away from the scanner (w = n·u > 0), its cosine with the beam is
// w / |n|, the footprint's stretch the inverse. Writes n pixels' normals
// (as three arrays), confidences, footprints and flags. Branch-free over
// plain, unaliased arrays, so that the loop vectorizes. Masked pixels that
// are not mixed and have no clean window are left for the covariance fit
// (no flag).
SCANBENCH_VECTOR_CLONES void window_normals(int n, const RowConstants& constants,
                                            WindowNormalInputs in, WindowNormalOutputs out) {
  const float cos_el = constants.cos_el, sin_el = constants.sin_el;
  for (int j = 0; j < n; ++j) {
    const float k2 = (static_cast<float>(in.used[j]) - 1.0f) * 0.25f;  // k(k + 1)
    const float mean_az = 1.0f - constants.az_step_sq * k2 * (1.0f / 6.0f);
    const float mean_el = 1.0f - constants.el_step_sq * k2 * (1.0f / 6.0f);
    const float slope_az = 1.0f - constants.az_step_sq * (3.0f * k2 - 1.0f) * (1.0f / 30.0f);
    const float slope_el = 1.0f - constants.el_step_sq * (3.0f * k2 - 1.0f) * (1.0f / 30.0f);
    // The rotated pair (A Cθ/N cos φ0 + E sin φ0, −A Cθ/N sin φ0 + E cos φ0).
    const float u = in.mean[j] / mean_el;
    const float v = in.per_row[j] * constants.el_gradient / slope_el;
    const float along = (u * cos_el - v * sin_el) / mean_az;                               // A
    const float up = u * sin_el + v * cos_el;                                              // E
    const float across = in.per_column[j] * constants.az_gradient / (mean_el * slope_az);  // B
    const float ca = in.cos_az[j], sa = in.sin_az[j];
    const float px = along * ca - across * sa, py = along * sa + across * ca;
    const float q = px * px + py * py + up * up;
    const float inverse = inverse_sqrt(q);
    const float cos_incidence = (along * cos_el + up * sin_el) * inverse;  // w / |n|
    // A blend lies on no surface: a mixed pixel gets no normal of its own.
    const std::uint32_t ok =
        all_bits((in.used[j] >= constants.min_used) & (cos_incidence > 0.0f) &
                 (q <= std::numeric_limits<float>::max()) & (in.mixed[j] == 0));
    const std::uint32_t is_valid = all_bits(in.valid[j] != 0);
    const std::uint32_t pending =
        all_bits((in.used[j] == 0) & (in.mask[j] != 0) & (in.mixed[j] == 0));
    out.nx[j] = select_bits(-px * inverse, ok);
    out.ny[j] = select_bits(-py * inverse, ok);
    out.nz[j] = select_bits(-up * inverse, ok);
    out.confidence[j] = select_bits(std::max(1e-6f, cos_incidence), ok);
    const float stretch = select_bits(1.0f / cos_incidence, ok) + select_bits(1.0f, ~ok);
    out.footprint_m[j] = select_bits(
        in.range_m[j] * constants.half_spacing_rad * std::min(stretch, constants.max_stretch),
        is_valid);
    const std::uint32_t edge = all_bits((in.mask[j] != 0) & (in.clean[j] == 0));
    out.flags[j] =
        static_cast<std::uint8_t>((in.mixed[j] != 0 ? kFlagMixedPixel : 0) | (edge & kFlagEdge) |
                                  (is_valid & ~ok & ~pending & kFlagNoNormal));
  }
}

RowConstants row_constants(const StageContext& c, int row) {
  return {c.directions.cos_el[row],
          c.directions.sin_el[row],
          c.factors.azimuth_gradient[row],
          c.factors.elevation_gradient,
          c.factors.azimuth_step_sq,
          c.factors.elevation_step_sq,
          c.factors.half_spacing_rad[row],
          static_cast<float>(c.settings.max_footprint_stretch),
          static_cast<std::uint16_t>(std::clamp(c.settings.min_neighbours, 1, 65535))};
}

// A spherical row segment, pixels (row, begin … begin + n − 1), with its
// window fits' pixel counts (0: no clean window).
struct RowSegment {
  int row, begin, n;
  std::size_t first;  // the scan index of its first pixel
  const std::uint16_t* used;
  float half_spacing_rad;  // see RowFactors

  // Segment pixel j is masked, not mixed, and has no window fit.
  bool pending(const StageContext& c, int j) const {
    return j < n && used[j] == 0 && c.in.mask[first + j] && !c.in.mixed[first + j];
  }
};

// Stores the covariance fit of pending segment pixel j, together with those
// of the pending pixels among the next kCovarianceLanes − 1 where their
// windows allow it; returns how many pixels it has done.
int store_fallback_from(const StageContext& c, const RowSegment& s, int j) {
  const float* range_m = c.scan.range_m.data();
  const int col = s.begin + j;
  if (!covariance_lanes_fit(c.directions, s.row, col, c.scan.rows, c.settings)) {
    store_fit(c,
              covariance_fit(c.directions, range_m, c.in.mask.get(), c.in.fallback_log_range.get(),
                             s.row, col, c.scan.rows, c.settings),
              s.first + j, s.half_spacing_rad);
    return 1;
  }
  unsigned wanted = 0;
  for (int lane = 0; lane < kCovarianceLanes; ++lane)
    wanted |= s.pending(c, j + lane) ? 1u << lane : 0u;
  NormalFit fits[kCovarianceLanes];
  covariance_fits(c.directions, range_m, c.in.fallback_log_range.get(), s.row, col, c.scan.rows,
                  c.settings, wanted, fits);
  for (int lane = 0; lane < kCovarianceLanes; ++lane) {
    if (wanted & (1u << lane)) store_fit(c, fits[lane], s.first + j + lane, s.half_spacing_rad);
  }
  return kCovarianceLanes;
}

// The covariance fits of a spherical row segment's masked pixels without a
// clean window (cut by a discontinuity, an invalid region or the grid's
// border): the log-range slope of a lopsided window is biased by the
// curvature of ln r, a 3D plane fit is not. Runs of them go in lanes.
void store_fallback_fits(const StageContext& c, const RowSegment& s) {
  int j = 0;
  while (j < s.n) j += s.pending(c, j) ? store_fallback_from(c, s, j) : 1;
}

// A spherical scan's row segment: window normals in chunks (scratch arrays
// on the stack), then the covariance fit where no clean window exists.
void store_window_fits(const StageContext& c, int row, int begin, int end,
                       const WindowSlopeRow& s) {
  constexpr int kChunk = 128;
  const RowConstants constants = row_constants(c, row);
  const std::size_t first = c.scan.index(row, begin);
  for (int j0 = 0; j0 < end - begin; j0 += kChunk) {
    const int n = std::min(kChunk, end - begin - j0);
    const std::size_t i0 = first + j0;
    float nx[kChunk], ny[kChunk], nz[kChunk];
    const WindowNormalInputs inputs{s.mean + j0,
                                    s.per_column + j0,
                                    s.per_row + j0,
                                    s.used + j0,
                                    c.directions.cos_az.data() + begin + j0,
                                    c.directions.sin_az.data() + begin + j0,
                                    c.scan.range_m.data() + i0,
                                    c.scan.valid.data() + i0,
                                    c.in.mask.get() + i0,
                                    c.in.mixed.get() + i0,
                                    c.in.clean.get() + i0};
    window_normals(n, constants, inputs,
                   {nx, ny, nz, c.g.confidence.data() + i0, c.g.footprint_m.data() + i0,
                    c.g.flags.data() + i0});
    for (int j = 0; j < n; ++j) c.g.normal[i0 + j] = Eigen::Vector3f(nx[j], ny[j], nz[j]);
  }
  store_fallback_fits(c, {row, begin, end - begin, first, s.used, constants.half_spacing_rad});
  count_pixels(c, first, end - begin);
}

// A row of a per-pixel direction grid: covariance fits only.
void store_covariance_fits(const StageContext& c, int row) {
  for (int col = 0; col < c.scan.columns; ++col) {
    const std::size_t i = c.scan.index(row, col);
    c.g.normal[i] = Eigen::Vector3f::Zero();
    c.g.flags[i] = c.in.flags(i);
    if (!c.scan.valid[i]) continue;
    NormalFit fit;
    if (c.in.mask[i] && !c.in.mixed[i]) {
      fit = covariance_fit(c.directions, c.scan.range_m.data(), c.in.mask.get(),
                           c.in.fallback_log_range.get(), row, col, c.scan.rows, c.settings);
    }
    store_fit(c, fit, i, per_pixel_half_spacing_rad(c.scan, row, col));
  }
  count_pixels(c, c.scan.index(row, 0), c.scan.columns);
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

// The outputs; every pixel is written by the passes below.
void allocate(ScanGeometry& g, std::size_t n) {
  core::assign_mapped(g.footprint_m, n, 0.0f);
  core::reserve_mapped(g.normal, n);
  g.normal.resize(n);  // Eigen leaves it uninitialised; every pixel is written below
  core::assign_mapped(g.confidence, n, 0.0f);
  core::assign_mapped(g.flags, n, std::uint8_t{0});
}

}  // namespace

// The passes run over every held row, the fits and the counts over the
// band's rows only, whose values the result keeps.
GeometryResult compute_grid_geometry(const Scan& scan, const GeometrySettings& settings,
                                     const RowBand& band) {
  const auto start = std::chrono::steady_clock::now();
  GeometryResult result;
  ScanGeometry& g = result.geometry;
  FitInputs in(scan.pixel_count());
  // std::vector zero-fills the outputs on one thread (every pixel is then
  // written again); that runs beside the first passes, not before them.
  tbb::task_arena arena = core::worker_arena(settings.threads);
  arena.execute([&] {
    tbb::parallel_invoke([&] { allocate(g, scan.pixel_count()); },
                         [&] {
                           mark_mixed_and_mask(scan, settings, in);
                           mark_jumps(scan, settings, in);
                         });
  });
  const GridDirections directions(scan, band.first_row);
  const RowFactors factors(scan, band.first_row);
  Counts counts;
  const StageContext context{scan, settings, in, directions, factors, g, counts};
  const int begin = band.begin - band.first_row, end = band.end - band.first_row;
  if (scan.is_spherical()) {
    const std::vector<int> radii = cascade_radii(settings);
    visit_window_slopes(
        scan.rows, scan.columns, radii, {in.clean.get(), scan.pixel_count()},
        {in.inverse_range.get(), scan.pixel_count()}, settings.threads,
        [&](int row, int col_begin, int col_end, const WindowSlopeRow& slopes) {
          store_window_fits(context, row, col_begin, col_end, slopes);
        },
        band);
  } else {
    parallel_rows(end - begin, settings.threads,
                  [&](int k) { store_covariance_fits(context, begin + k); });
  }
  if (begin > 0 || end < scan.rows) {  // the band's rows only
    const auto keep = [&](auto& values) {
      const auto columns = static_cast<std::ptrdiff_t>(scan.columns);
      values.erase(values.begin() + end * columns, values.end());
      values.erase(values.begin(), values.begin() + begin * columns);
    };
    keep(g.footprint_m), keep(g.normal), keep(g.confidence), keep(g.flags);
  }
  result.valid_points = counts.valid, result.normals = counts.normals;
  result.mixed_pixels = counts.mixed, result.edge_pixels = counts.edges;
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::acquisition

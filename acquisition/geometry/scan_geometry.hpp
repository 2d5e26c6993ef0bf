// Per-point geometry from pixel adjacency (seed 004 §4.2): every pixel of a
// scan is a point with a size — the footprint that closes the gap to its
// neighbours — and a normal fitted from its neighbours in the scan grid, plus
// flags for the points that float between foreground and background at depth
// edges (mixed pixels, "veils").
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "acquisition/geometry/noise_estimate.hpp"
#include "acquisition/geometry/row_band.hpp"
#include "acquisition/range_noise.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Bits of ScanGeometry::flags.
enum GeometryFlag : std::uint8_t {
  kFlagMixedPixel = 1u << 0,  // floats between a foreground and a background surface
  kFlagEdge = 1u << 1,        // next to a depth discontinuity
  kFlagNoNormal = 1u << 2,    // too few consistent neighbours: normal is invalid
};

// Parallel arrays, rows × columns, row-major like the scan.
struct ScanGeometry {
  // Radius [m] of the disk that closes the gap to the neighbouring samples;
  // 0 where the pixel is invalid.
  std::vector<float> footprint_m;
  // Unit normal in the scan frame pointing towards the scanner (a scattered
  // scan's: to its origin, or to the side of the normals its file
  // recorded, scattered_geometry.hpp); the zero vector where the normal is
  // invalid (invalid pixel or kFlagNoNormal).
  std::vector<Eigen::Vector3f> normal;
  // [0, 1]: the share of the window the fit used times the cosine of the
  // incidence angle (grazing views estimate normals poorly); 0 where the
  // normal is invalid.
  std::vector<float> confidence;
  std::vector<std::uint8_t> flags;
  // The scan's σ(range), with which the flags were decided: estimated from
  // the scan (GeometrySettings::estimate_range_noise) or the settings'.
  // Later stages that compare this scan's ranges with another's (the
  // merge, carrying objects, growing regions) take it from here.
  RangeNoise range_noise;

  bool has_normal(std::size_t i) const { return confidence[i] > 0.0f; }
  bool is_mixed(std::size_t i) const { return (flags[i] & kFlagMixedPixel) != 0; }
};

// The rule for which points belong in a model (registration, the merge,
// segmentation, rendering): a return that is not a mixed pixel. Asserts
// nothing; `i` must index both.
inline bool in_model(const Scan& scan, const ScanGeometry& geometry, std::size_t i) {
  return scan.valid[i] != 0 && !geometry.is_mixed(i);
}

// Window counts are 16-bit: (2 · 127 + 1)² < 65536.
inline constexpr int kMaxWindowRadius = 127;

struct GeometrySettings {
  // Neighbourhood of the plane fit: (2 · window_radius + 1)² pixels, used
  // wherever that whole window is valid and free of depth discontinuities (a
  // wide window averages the range noise away on the large surfaces of
  // outdoor scenes). Where it is not, the fit tries windows of half the
  // radius, down to edge_window_radius; where even that one is cut (next to
  // a discontinuity, an invalid region or the grid's border), a covariance
  // fit of the consistent neighbours in it. The cost per pixel does not
  // depend on the radii (running box sums).
  int window_radius = 16;  // at most kMaxWindowRadius
  int edge_window_radius = 2;
  // A depth discontinuity: the second difference of log-range along a row or
  // column exceeds depth_jump_sigmas times its noise (√6 · σ(range) / range),
  // or depth_jump_relative, whichever is smaller, but never less than 5/6 of
  // the former (5 σ at the default: no jumps inside the noise). A grazing
  // but smooth surface has a steady range gradient and no second difference.
  double depth_jump_sigmas = 6.0;
  // Neighbours whose range differs from the centre's by more than
  // depth_jump_relative · range · (pixel distance) are across a depth
  // discontinuity and left out of the covariance fit.
  double depth_jump_relative = 0.02;
  // Fewer valid, consistent neighbours than this gives an invalid normal.
  int min_neighbours = 5;
  // Largest footprint, in multiples of the grazing-free footprint, so that a
  // surface seen edge-on does not produce metre-wide splats.
  double max_footprint_stretch = 4.0;
  // Detect and flag mixed pixels (they stay in the scan; later stages leave
  // them out of the model).
  bool flag_mixed_pixels = true;
  // The scanner's range noise σ. A pixel is a mixed pixel when, along some
  // grid line, it lies between its neighbours, off the linear continuation
  // of both sides by more than mixed_pixel_sigmas · σ and
  // mixed_pixel_relative · range, and the two continuations are
  // depth_jump_relative · range apart (mixed_pixels.hpp).
  RangeNoise range_noise;
  // Estimate σ(range) from the scan (noise_estimate.hpp; a scattered
  // scan's from its points' planes, scattered_geometry.hpp) and use that;
  // range_noise is then only the fallback for a scan that gives no
  // estimate. `scanbench geometry` does so unless told the noise.
  bool estimate_range_noise = false;
  double mixed_pixel_sigmas = 3.0;
  double mixed_pixel_relative = 0.004;
  // Worker threads; 0 = all cores. Results do not depend on it.
  int threads = 0;
};

struct GeometryResult {
  ScanGeometry geometry;
  NoiseEstimate noise;  // the σ(range) used: estimated, or the settings'.
  std::size_t valid_points = 0;
  std::size_t normals = 0;           // valid points given a normal
  std::size_t recorded_normals = 0;  // of them, normals the file recorded
  std::size_t mixed_pixels = 0;
  std::size_t edge_pixels = 0;
  double seconds = 0.0;
};

// Computes footprints, normals, confidences and flags for every pixel. Works
// on spherical and per-pixel-direction scans (for the latter the fit runs on
// the points themselves), and on scattered scans from each point's nearest
// neighbours (scattered_geometry.hpp), keeping what its file `recorded`.
// Asserts the scan is consistent, and `recorded` empty for a grid (or one
// value per pixel).
GeometryResult compute_geometry(const Scan& scan, const GeometrySettings& settings = {},
                                const RecordedGeometry& recorded = {});

// ---- A grid scan too large to hold whole, band by band (docs/scale.md) ----
//
// The geometry of a pixel depends on the rows around it only, so a grid
// scan's geometry can be computed a band of rows at a time, each band from
// its rows and geometry_halo_rows() on either side; with band limits at
// geometry_band_cuts() (the window fits' tiles) and the σ(range) of the
// whole scan (NoiseTiles, noise_estimate.hpp), the bands together are
// compute_geometry's result bit for bit.

// Rows a band needs on either side of the rows it computes.
int geometry_halo_rows(const GeometrySettings& settings);

// Where bands may begin and end in a grid of `rows` rows: ascending, from 0
// to `rows` (about every 256 rows).
std::vector<int> geometry_band_cuts(int rows);

// The geometry of grid rows [band.begin, band.end) of a grid scan (not
// scattered): `held` holds the grid's rows from band.first_row =
// max(0, begin − halo) to min(band.rows, end + halo), with the grid's angle
// model (per-pixel directions of the held rows only). The result's arrays
// and counts are the band's rows'; its noise, settings.range_noise, which
// is used as it is (never estimated). Asserts the band's limits are cuts
// and its held rows as said.
GeometryResult compute_geometry_rows(const Scan& held, const RowBand& band,
                                     const GeometrySettings& settings);

}  // namespace scanbench::acquisition

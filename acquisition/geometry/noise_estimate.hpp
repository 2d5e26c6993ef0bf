// The range noise of a scan, estimated from the scan itself: what the
// geometry stage's depth-jump and mixed-pixel tests compare against, for any
// instrument, without being told which one recorded it.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "acquisition/geometry/row_band.hpp"
#include "acquisition/range_noise.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// σ measured in one band of ranges.
struct NoiseBand {
  double range_m = 0.0;  // the band's mean range
  double sigma_m = 0.0;
  std::size_t samples = 0;
};

struct NoiseEstimate {
  RangeNoise noise;  // the fit, or the fallback when !estimated
  bool estimated = false;
  std::vector<NoiseBand> bands;  // the bands the fit used, nearest first
  std::size_t samples = 0;       // residuals measured, in all bands
};

// Estimates σ(range) of a grid scan. Along every row and every column, five
// consecutive valid returns give the residual of a local fit: the fourth
// difference of their inverse ranges u = 1/r, u₋₂ − 4u₋₁ + 6u₀ − 4u₊₁ + u₊₂,
// times r₀². A plane's 1/r is a sum of sines and cosines of the beam angles,
// which the fourth difference all but removes at any incidence, grazing
// ground included (a range's own fourth difference does not: at 3.7° over
// ground and 0.25° steps it is 12 mm), as it removes any cubic of a gently
// curved surface. What remains is noise, of standard deviation √70 · σ,
// except across depth jumps, on mixed pixels and on rough surfaces (foliage,
// rubble), which only make it larger.
//   Each tile of 16 × 16 pixels gets σ from the median of its |residuals|
// (0.674 √70 σ for Gaussian noise), at its mean range. Tiles fall into bands
// of range 19 % wide; a band of at least 8 tiles takes the 30th percentile
// of its tiles' σ, so rough or broken ground in up to about two thirds of a
// band's tiles does not drag it up; a band whose σ comes out below 0.1 mm
// (ranges quantised coarser than their noise) is left out. The bands are
// fitted with σ(r) = a + b r + c r², a, b, c ≥ 0 (a ≥ 0.1 mm), least squares
// relative to each band's σ and weighted by its residuals, a term added only
// where the bands support it (one band: a constant). The percentile of
// tiles' medians runs a few per cent low (measured: 0.94–0.98 of the truth).
// A scan with no usable band (a scattered scan, which has no grid lines and
// is estimated from its points' planes instead, scattered_geometry.hpp; a
// tiny, empty or coarsely quantised one) keeps `fallback`. The result does
// not depend on `threads` (0: all cores).
NoiseEstimate estimate_range_noise(const Scan& scan, const RangeNoise& fallback = {},
                                   int threads = 0);

// The same estimate made band by band, for a scan too large to hold whole:
// add() each band of rows (its limits multiples of kRowMultiple, or the
// grid's end; the held rows kHaloRows beyond them, or the grid's end), in
// any order, then finish(): the estimate of the whole scan, bit for bit.
class NoiseTiles {
 public:
  static constexpr int kRowMultiple = 16;  // the tiles' height
  static constexpr int kHaloRows = 2;      // the residuals' reach

  // Of a grid scan of rows × columns (scattered: `scattered`, then no tile is kept).
  NoiseTiles(int rows, int columns, bool scattered);

  // The tiles of rows [band.begin, band.end) of `held`, which holds rows
  // from band.first_row (asserted).
  void add(const Scan& held, const RowBand& band, int threads = 0);

  NoiseEstimate finish(const RangeNoise& fallback) const;

 private:
  int rows_, columns_, tile_columns_;
  bool usable_;
  // Per tile, row-major: its σ at its mean range and its residuals (a
  // NoiseBand of one tile); none until added, or too few residuals.
  std::vector<std::optional<NoiseBand>> tiles_;
};

}  // namespace scanbench::acquisition

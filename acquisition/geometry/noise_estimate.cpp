#include "acquisition/geometry/noise_estimate.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "core/parallel.hpp"

namespace scanbench::acquisition {
namespace {

// Bands of range: band k holds [0.1 m · 2^(k/4), 0.1 m · 2^((k+1)/4)), up to 6.5 km.
constexpr int kBands = 64;
constexpr double kNearestM = 0.1;
constexpr double kBandsPerOctave = 4.0;
constexpr int kTile = 16;                 // tiles of 16 × 16 pixels
constexpr std::size_t kTileMinimum = 64;  // residuals for a tile's σ
constexpr std::size_t kBandMinimumTiles = 8;
// The median of |N(0, 1)| is Φ⁻¹(0.75); the fourth difference of
// independent readings has variance (1 + 16 + 36 + 16 + 1) σ² = 70 σ².
constexpr double kMedianOfUnitNormal = 0.674489750196082;
const double kResidualPerSigma = kMedianOfUnitNormal * std::sqrt(70.0);
constexpr double kTileQuantile = 0.3;
constexpr double kMinSigmaM = 1e-4;

// One tile's σ, at its mean range.
struct TileSigma {
  double range_m = 0.0;
  double sigma_m = 0.0;
  std::size_t samples = 0;
};

// The fourth difference of five inverse ranges, times the centre's range
// squared (a range error ε moves 1/r by −ε / r²), or NaN where one has no
// return.
inline double residual(const Scan& scan, std::size_t i, std::ptrdiff_t step) {
  const auto inverse = [&](std::ptrdiff_t k) {
    const auto j = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(i) + k * step);
    return scan.valid[j] ? 1.0 / static_cast<double>(scan.range_m[j])
                         : std::numeric_limits<double>::quiet_NaN();
  };
  const double r = scan.range_m[i];
  return r * r *
         (inverse(-2) - 4.0 * inverse(-1) + 6.0 * inverse(0) - 4.0 * inverse(1) + inverse(2));
}

// The σ of the tile whose top left pixel is (row0, col0): the median of its
// |residuals| along rows and columns.
std::optional<TileSigma> tile_sigma(const Scan& scan, int row0, int col0,
                                    std::vector<double>& residuals) {
  residuals.clear();
  double range_sum = 0.0;
  const auto stride = static_cast<std::ptrdiff_t>(scan.columns);
  for (int row = row0; row < std::min(scan.rows, row0 + kTile); ++row) {
    for (int col = col0; col < std::min(scan.columns, col0 + kTile); ++col) {
      const std::size_t i = scan.index(row, col);
      if (!scan.valid[i]) continue;
      for (const bool along_row : {true, false}) {
        const bool inside =
            along_row ? col >= 2 && col + 2 < scan.columns : row >= 2 && row + 2 < scan.rows;
        if (!inside) continue;
        const double r = residual(scan, i, along_row ? 1 : stride);
        if (!std::isfinite(r)) continue;
        residuals.push_back(std::abs(r));
        range_sum += scan.range_m[i];
      }
    }
  }
  if (residuals.size() < kTileMinimum) return std::nullopt;
  const auto middle = residuals.begin() + static_cast<std::ptrdiff_t>(residuals.size() / 2);
  std::nth_element(residuals.begin(), middle, residuals.end());
  return TileSigma{range_sum / static_cast<double>(residuals.size()), *middle / kResidualPerSigma,
                   residuals.size()};
}

// σ(r) = a + b r + c r² with a, b, c ≥ 0: the least-squares fit relative to
// each band's σ, weighted by its samples, over the subsets of free terms
// (the others 0) that have at least as many bands as terms, simplest first;
// a subset replaces the one before only when its terms are all ≥ 0 and it
// lowers the cost by more than 10 %. One band gives a constant σ, not
// whichever one-term model rounding favours. None when no subset fits.
std::optional<RangeNoise> fit(const std::vector<NoiseBand>& bands) {
  constexpr double kClearlyBetter = 0.9;
  constexpr std::array<int, 7> kSubsets = {0b001, 0b010, 0b100, 0b011, 0b101, 0b110, 0b111};
  double best_cost = std::numeric_limits<double>::infinity();
  std::optional<Eigen::Vector3d> best;
  for (const int subset : kSubsets) {
    if (static_cast<std::size_t>(std::popcount(static_cast<unsigned>(subset))) > bands.size())
      continue;
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (const NoiseBand& b : bands) {
      const double w = static_cast<double>(b.samples) / (b.sigma_m * b.sigma_m);
      Eigen::Vector3d x(1.0, b.range_m, b.range_m * b.range_m);
      for (int t = 0; t < 3; ++t) x[t] = (subset >> t) & 1 ? x[t] : 0.0;
      normal += w * x * x.transpose();
      rhs += w * x * b.sigma_m;
    }
    for (int t = 0; t < 3; ++t) {
      if (!((subset >> t) & 1)) normal(t, t) = 1.0;  // the term stays 0
    }
    const Eigen::Vector3d c = normal.ldlt().solve(rhs);
    if (!c.allFinite() || c.minCoeff() < 0.0) continue;
    double cost = 0.0;
    for (const NoiseBand& b : bands) {
      const double e =
          (c[0] + c[1] * b.range_m + c[2] * b.range_m * b.range_m - b.sigma_m) / b.sigma_m;
      cost += static_cast<double>(b.samples) * e * e;
    }
    if (!best || cost < kClearlyBetter * best_cost) {
      best_cost = cost;
      best = c;
    }
  }
  if (!best) return std::nullopt;
  RangeNoise noise;
  noise.noise_m = std::max((*best)[0], kMinSigmaM);
  noise.noise_per_m = (*best)[1];
  noise.noise_per_m2 = (*best)[2];
  return noise;
}

}  // namespace

NoiseEstimate estimate_range_noise(const Scan& scan, const RangeNoise& fallback, int threads) {
  NoiseTiles tiles(scan.rows, scan.columns, scan.is_scattered());
  tiles.add(scan, RowBand::whole(scan.rows), threads);
  return tiles.finish(fallback);
}

NoiseTiles::NoiseTiles(int rows, int columns, bool scattered)
    : rows_(rows),
      columns_(columns),
      tile_columns_((columns + kTile - 1) / kTile),
      usable_(!scattered && rows >= 5 && columns >= 5) {
  static_assert(kRowMultiple == kTile);
  if (usable_) tiles_.resize(static_cast<std::size_t>((rows + kTile - 1) / kTile) * tile_columns_);
}

void NoiseTiles::add(const Scan& held, const RowBand& band, int threads) {
  if (!usable_) return;
  assert(held.columns == columns_ && band.rows == rows_ && band.begin % kTile == 0 &&
         (band.end % kTile == 0 || band.end == rows_) && band.first_row >= 0 &&
         band.first_row <= std::max(0, band.begin - kHaloRows) &&
         band.first_row + held.rows >= std::min(rows_, band.end + kHaloRows) &&
         "a band of whole tiles with the rows its residuals reach");
  // tile_sigma's border tests on the held rows are the grid's: the held
  // rows reach kHaloRows beyond the band, or the grid's end.
  const int first_tile = band.begin / kTile, end_tile = (band.end + kTile - 1) / kTile;
  core::parallel_for_index(end_tile - first_tile, threads, [&](int k) {
    const int tr = first_tile + k;
    std::vector<double> residuals;
    for (int tc = 0; tc < tile_columns_; ++tc) {
      const std::optional<TileSigma> tile =
          tile_sigma(held, tr * kTile - band.first_row, tc * kTile, residuals);
      if (tile) {
        tiles_[static_cast<std::size_t>(tr) * tile_columns_ + tc] =
            NoiseBand{tile->range_m, tile->sigma_m, tile->samples};
      }
    }
  });
}

NoiseEstimate NoiseTiles::finish(const RangeNoise& fallback) const {
  NoiseEstimate out;
  out.noise = fallback;
  std::array<std::vector<TileSigma>, kBands> by_band;
  for (const std::optional<NoiseBand>& tile : tiles_) {
    if (!tile) continue;
    const int band =
        static_cast<int>(std::floor(kBandsPerOctave * std::log2(tile->range_m / kNearestM)));
    if (band >= 0 && band < kBands) {
      by_band[static_cast<std::size_t>(band)].push_back(
          {tile->range_m, tile->sigma_m, tile->samples});
    }
  }
  for (std::vector<TileSigma>& band : by_band) {
    if (band.size() < kBandMinimumTiles) continue;
    std::sort(band.begin(), band.end(),
              [](const TileSigma& a, const TileSigma& b) { return a.sigma_m < b.sigma_m; });
    const TileSigma& low = band[static_cast<std::size_t>(kTileQuantile * (band.size() - 1))];
    // Ranges quantised coarser than their noise (equal readings along a
    // head-on wall) leave medians of 0: no estimate in that band.
    if (low.sigma_m < kMinSigmaM) continue;
    double range_sum = 0.0;
    std::size_t samples = 0;
    for (const TileSigma& t : band) {
      range_sum += t.range_m;
      samples += t.samples;
    }
    out.bands.push_back({range_sum / static_cast<double>(band.size()), low.sigma_m, samples});
    out.samples += samples;
  }
  const std::optional<RangeNoise> fitted = out.bands.empty() ? std::nullopt : fit(out.bands);
  if (!fitted) return out;
  out.noise = *fitted;
  out.estimated = true;
  return out;
}

}  // namespace scanbench::acquisition

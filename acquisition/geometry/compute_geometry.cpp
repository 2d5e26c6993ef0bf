// The geometry stage's entry points (scan_geometry.hpp): a scan whole, or
// a grid a band of rows at a time (docs/scale.md, "Big scans").
#include <algorithm>
#include <cassert>
#include <chrono>

#include "acquisition/geometry/grid_geometry.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/geometry/scattered_geometry.hpp"
#include "acquisition/geometry/window_moments.hpp"
#include "core/timing.hpp"

namespace scanbench::acquisition {

GeometryResult compute_geometry(const Scan& scan, const GeometrySettings& settings,
                                const RecordedGeometry& recorded) {
  assert(check_consistency(scan).empty() && (recorded.empty() || scan.is_scattered()) &&
         settings.edge_window_radius >= 1 &&
         settings.window_radius >= settings.edge_window_radius &&
         settings.window_radius <= kMaxWindowRadius);
  const auto start = std::chrono::steady_clock::now();
  GeometryResult result;
  if (scan.is_scattered()) {
    result = compute_scattered_geometry(scan, settings, recorded);  // estimates its own noise
  } else {
    GeometrySettings used = settings;
    NoiseEstimate noise;
    noise.noise = settings.range_noise;
    if (settings.estimate_range_noise) {
      noise = estimate_range_noise(scan, settings.range_noise, settings.threads);
      used.range_noise = noise.noise;
    }
    result = compute_grid_geometry(scan, used, RowBand::whole(scan.rows));
    result.noise = std::move(noise);
  }
  result.geometry.range_noise = result.noise.noise;
  result.seconds = core::seconds_since(start);
  return result;
}

int geometry_halo_rows(const GeometrySettings& settings) {
  // A window fit reads the clean marks window_radius rows away (its
  // integral images one more), a clean mark the rows next to it, a mixed
  // pixel three rows on either side (mixed_pixels.cpp): rows nearer the
  // held rows' ends than that see a border where the grid has none.
  return settings.window_radius + 8;
}

std::vector<int> geometry_band_cuts(int rows) {
  return window_tile_row_cuts(rows);
}

GeometryResult compute_geometry_rows(const Scan& held, const RowBand& band,
                                     const GeometrySettings& settings) {
  [[maybe_unused]] const int halo = geometry_halo_rows(settings);
  [[maybe_unused]] const std::vector<int> cuts = geometry_band_cuts(band.rows);
  assert(!held.is_scattered() && check_consistency(held).empty() &&
         settings.edge_window_radius >= 1 &&
         settings.window_radius >= settings.edge_window_radius &&
         settings.window_radius <= kMaxWindowRadius && band.begin <= band.end &&
         std::binary_search(cuts.begin(), cuts.end(), band.begin) &&
         std::binary_search(cuts.begin(), cuts.end(), band.end) &&
         band.first_row == std::max(0, band.begin - halo) &&
         band.first_row + held.rows == std::min(band.rows, band.end + halo) &&
         "a band between tile cuts, held with its halo");
  const auto start = std::chrono::steady_clock::now();
  GeometryResult result = compute_grid_geometry(held, settings, band);
  result.noise.noise = settings.range_noise;
  result.geometry.range_noise = settings.range_noise;
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::acquisition

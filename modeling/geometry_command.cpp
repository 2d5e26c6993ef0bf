#include "modeling/geometry_command.hpp"

#include <chrono>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/scan_rows.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kStage = "geometry";

// Limits of bands of about `band_pixels` pixels from `cuts` (ascending,
// from 0 to the rows), each band at least one cut interval.
std::vector<int> band_limits(const std::vector<int>& cuts, int columns, std::size_t band_pixels) {
  std::vector<int> limits = {cuts.front()};
  const std::size_t per_row = static_cast<std::size_t>(std::max(columns, 1));
  for (std::size_t k = 1; k < cuts.size(); ++k) {
    // Grows the last band to cuts[k] where that stays within band_pixels.
    const bool grow =
        limits.size() > 1 &&
        static_cast<std::size_t>(cuts[k] - limits[limits.size() - 2]) * per_row <= band_pixels;
    if (grow) {
      limits.back() = cuts[k];
    } else {
      limits.push_back(cuts[k]);
    }
  }
  return limits;
}

// σ(range) of scan `id` (a grid), estimated band by band.
acquisition::NoiseEstimate estimate_noise_by_bands(const store::Project& project, std::int64_t id,
                                                   const acquisition::GeometrySettings& settings,
                                                   std::size_t band_pixels) {
  ScanRows rows(project, id);
  const acquisition::Scan& scan = rows.description();
  acquisition::NoiseTiles tiles(scan.rows, scan.columns, false);
  std::vector<int> cuts;
  for (int row = 0; row < scan.rows; row += acquisition::NoiseTiles::kRowMultiple)
    cuts.push_back(row);
  cuts.push_back(scan.rows);
  const std::vector<int> limits = band_limits(cuts, scan.columns, band_pixels);
  constexpr int kHalo = acquisition::NoiseTiles::kHaloRows;
  for (std::size_t k = 0; k + 1 < limits.size(); ++k) {
    const int first = std::max(0, limits[k] - kHalo);
    const acquisition::Scan& held = rows.hold(first, std::min(scan.rows, limits[k + 1] + kHalo));
    tiles.add(held, {scan.rows, first, limits[k], limits[k + 1]}, settings.threads);
  }
  return tiles.finish(settings.range_noise);
}

// The geometry of grid scan `id`, band by band into `out`: the counts and
// σ(range) of compute_geometry, whose result it is bit for bit.
// Cancellable between bands (core::Cancelled).
acquisition::GeometryResult geometry_by_bands(const store::Project& project, std::int64_t id,
                                              acquisition::GeometrySettings settings,
                                              std::size_t band_pixels, core::Progress& progress,
                                              store::GeometryLayerWriter& out) {
  const auto start = std::chrono::steady_clock::now();
  acquisition::GeometryResult result;
  result.noise.noise = settings.range_noise;
  if (settings.estimate_range_noise) {
    result.noise = estimate_noise_by_bands(project, id, settings, band_pixels);
    settings.range_noise = result.noise.noise;
  }
  ScanRows rows(project, id);
  const acquisition::Scan& scan = rows.description();
  const std::vector<int> limits =
      band_limits(acquisition::geometry_band_cuts(scan.rows), scan.columns, band_pixels);
  const int halo = acquisition::geometry_halo_rows(settings);
  for (std::size_t k = 0; k + 1 < limits.size(); ++k) {
    progress.throw_if_cancelled(kStage);
    const int first = std::max(0, limits[k] - halo);
    const acquisition::Scan& held = rows.hold(first, std::min(scan.rows, limits[k + 1] + halo));
    const acquisition::GeometryResult band = acquisition::compute_geometry_rows(
        held, {scan.rows, first, limits[k], limits[k + 1]}, settings);
    out.write(band.geometry);
    result.valid_points += band.valid_points, result.normals += band.normals;
    result.mixed_pixels += band.mixed_pixels, result.edge_pixels += band.edge_pixels;
  }
  result.geometry.range_noise = result.noise.noise;
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace

GeometryCommandResult geometry_project(store::Project& project,
                                       const acquisition::GeometrySettings& settings,
                                       core::Progress& progress, std::size_t band_pixels) {
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t revision = project.revision();
  const std::vector<store::StoredScanSummary> scans = project.scans();
  if (scans.empty())
    throw core::InputError(project.path().string(), {}, "the project has no scans");
  GeometryCommandResult result;
  // One part per scan: a band of one scan's rows in memory at a time (a
  // cloud's points whole), and the write lock held only while its layers
  // are written.
  store::Project::LongCommand command =
      project.begin_long_command(kStage, settings_to_json(settings), revision);
  result.command_id = command.command_id();
  for (const store::StoredScanSummary& stored : scans) {
    progress.throw_if_cancelled(kStage);
    const acquisition::Scan description = project.load_scan_description(stored.id);
    acquisition::GeometryResult geometry;
    std::vector<store::EncodedLayer> whole;           // a cloud's layers, or
    std::optional<store::GeometryLayerWriter> bands;  // a grid's, written by rows
    if (description.is_scattered()) {                 // a cloud: its neighbours are anywhere in it
      const acquisition::Scan scan = project.load_scan(stored.id, {false, false});
      geometry = acquisition::compute_geometry(scan, settings,
                                               store::load_recorded_geometry(project, stored.id));
      whole = store::encode_geometry(geometry.geometry);
    } else {
      if (!store::load_recorded_geometry(project, stored.id).empty()) {
        core::FilePosition position;
        position.detail = "scan " + std::to_string(stored.id);
        throw core::InputError(project.path().string(), position,
                               "project is damaged: a scan grid has recorded normals or "
                               "footprints, which only an unstructured cloud's file gives");
      }
      bands.emplace(description.rows, description.columns);
      geometry = geometry_by_bands(project, stored.id, settings, band_pixels, progress, *bands);
    }
    store::Project::Edit part = command.part();
    for (const store::EncodedLayer& layer : whole) project.put_layer(part, stored.id, layer);
    if (bands) bands->put(project, part, stored.id);
    part.commit_part();
    result.scans.push_back({stored.id, description.name, geometry.valid_points, geometry.normals,
                            geometry.recorded_normals, geometry.mixed_pixels, geometry.edge_pixels,
                            geometry.noise.noise, geometry.noise.estimated, geometry.seconds});
    progress.update({kStage, result.scans.size(), scans.size(), description.name});
  }
  progress.throw_if_cancelled(kStage);
  store::Project::Edit finish = command.finish();  // refuses when its scans changed meanwhile
  for (const store::StoredScanSummary& stored : scans) {
    project.remove_layer(finish, stored.id, store::layer::kKeep);  // decided on the old geometry
  }
  result.seconds = core::seconds_since(start);
  finish.commit(result_json(result));
  return result;
}

}  // namespace scanbench::modeling

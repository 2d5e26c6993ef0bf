#include "modeling/geometry_stage.hpp"

#include <chrono>
#include <nlohmann/json.hpp>

#include "core/timing.hpp"
#include "modeling/project.hpp"

namespace scanbench::modeling {

std::string geometry_settings_json(const acquisition::GeometrySettings& s) {
  return nlohmann::json{{"window_radius", s.window_radius},
                        {"edge_window_radius", s.edge_window_radius},
                        {"depth_jump_sigmas", s.depth_jump_sigmas},
                        {"depth_jump_relative", s.depth_jump_relative},
                        {"min_neighbours", s.min_neighbours},
                        {"max_footprint_stretch", s.max_footprint_stretch},
                        {"flag_mixed_pixels", s.flag_mixed_pixels},
                        {"range_noise_m", s.range_noise.noise_m},
                        {"range_noise_per_m", s.range_noise.noise_per_m},
                        {"mixed_pixel_sigmas", s.mixed_pixel_sigmas}}
      .dump();
}

GeometryStageResult compute_project_geometry(const std::filesystem::path& project_path,
                                             const GeometryStageSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  Project project = Project::open(project_path);
  const std::vector<StoredScanSummary> scans = project.scans();
  const std::string settings_json = geometry_settings_json(settings.geometry);
  GeometryStageResult result;
  Project::Transaction transaction = project.begin();
  for (const StoredScanSummary& stored : scans) {
    const acquisition::Scan scan = project.load_scan(stored.id);
    const acquisition::GeometryResult geometry =
        acquisition::compute_geometry(scan, settings.geometry);
    project.store_geometry(stored.id, geometry, settings_json);
    result.scans.push_back({stored.id, scan.name, geometry.valid_points, geometry.normals,
                            geometry.mixed_pixels, geometry.edge_pixels, geometry.seconds});
    if (settings.on_scan_done) settings.on_scan_done(result.scans.size(), scans.size(), scan.name);
  }
  transaction.commit();
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::modeling

#include "modeling/geometry_command.hpp"

#include <chrono>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kStage = "geometry";

}  // namespace

GeometryCommandResult geometry_project(store::Project& project,
                                       const acquisition::GeometrySettings& settings,
                                       core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t revision = project.revision();
  const std::vector<store::StoredScanSummary> scans = project.scans();
  if (scans.empty())
    throw core::InputError(project.path().string(), {}, "the project has no scans");
  GeometryCommandResult result;
  // One part per scan: one scan's geometry in memory at a time, and the
  // write lock held only while its layers are written.
  store::Project::LongCommand command =
      project.begin_long_command(kStage, settings_to_json(settings), revision);
  result.command_id = command.command_id();
  for (const store::StoredScanSummary& stored : scans) {
    progress.throw_if_cancelled(kStage);
    const acquisition::Scan scan = project.load_scan(stored.id);
    const acquisition::RecordedGeometry recorded =
        store::load_recorded_geometry(project, stored.id);
    if (!recorded.empty() && !scan.is_scattered()) {
      core::FilePosition position;
      position.detail = "scan " + std::to_string(stored.id);
      throw core::InputError(project.path().string(), position,
                             "project is damaged: a scan grid has recorded normals or footprints, "
                             "which only an unstructured cloud's file gives");
    }
    const acquisition::GeometryResult geometry =
        acquisition::compute_geometry(scan, settings, recorded);
    const std::vector<store::EncodedLayer> layers = store::encode_geometry(geometry.geometry);
    store::Project::Edit part = command.part();
    for (const store::EncodedLayer& layer : layers) project.put_layer(part, stored.id, layer);
    part.commit_part();
    result.scans.push_back({stored.id, scan.name, geometry.valid_points, geometry.normals,
                            geometry.recorded_normals, geometry.mixed_pixels, geometry.edge_pixels,
                            geometry.noise.noise, geometry.noise.estimated, geometry.seconds});
    progress.update({kStage, result.scans.size(), scans.size(), scan.name});
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

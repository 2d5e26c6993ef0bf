#include "modeling/loaded_scans.hpp"

#include "core/errors.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {

LoadedScans load_scans(const store::Project& project, int threads, const char* stage,
                       core::Progress& progress) {
  LoadedScans loaded;
  const std::vector<store::StoredScanSummary> scans = project.scans();
  if (scans.empty())
    throw core::InputError(project.path().string(), {}, "the project has no scans");
  for (const store::StoredScanSummary& stored : scans) {
    progress.throw_if_cancelled(stage);
    std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project, stored.id);
    if (!geometry) {
      throw core::InputError(project.path().string(), {},
                             "scan " + std::to_string(stored.id) + " (" + stored.summary.name +
                                 ") has no geometry: run scanbench geometry first");
    }
    loaded.ids.push_back(stored.id);
    loaded.scans.push_back(project.load_scan(stored.id));
    loaded.geometry.push_back(std::move(*geometry));
    progress.update({stage, loaded.ids.size(), scans.size(), "loaded " + stored.summary.name});
  }
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    loaded.prepared.push_back(
        registration::prepare_scan(loaded.scans[k], loaded.geometry[k], threads));
  }
  return loaded;
}

}  // namespace scanbench::modeling

#include "modeling/merge_command.hpp"

#include "modeling/command_json.hpp"
#include "modeling/loaded_scans.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {

MergeCommandResult merge_project(store::Project& project,
                                 const registration::MergeSettings& settings,
                                 core::Progress& progress) {
  constexpr const char* kStage = "merge";
  const std::int64_t revision = project.revision();
  const LoadedScans loaded = load_scans(project, settings.threads, kStage, progress);
  std::vector<Eigen::Isometry3d> poses;
  for (const acquisition::Scan& scan : loaded.scans) poses.push_back(scan.T_world_scan);
  registration::MergeResult merged =
      registration::merge_by_sampling_rate(loaded.prepared, poses, settings);
  MergeCommandResult out;
  out.points = merged.points;
  out.seconds = merged.seconds;
  std::vector<store::EncodedLayer> masks;
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    masks.push_back(store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8,
                                                      merged.scans[k].keep));
    MergeCommandScan scan{loaded.ids[k], loaded.scans[k].name, std::move(merged.scans[k])};
    scan.counts.keep.clear();
    out.scans.push_back(std::move(scan));
  }
  progress.throw_if_cancelled(kStage);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (std::size_t k = 0; k < loaded.ids.size(); ++k)
    project.put_layer(edit, loaded.ids[k], masks[k]);
  edit.commit(result_json(out));
  return out;
}

}  // namespace scanbench::modeling

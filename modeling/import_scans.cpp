#include "modeling/import_scans.hpp"

#include <chrono>
#include <nlohmann/json.hpp>
#include <set>

#include "core/errors.hpp"
#include "core/timing.hpp"
#include "modeling/settings_json.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kStage = "import";

std::string settings_json(std::span<const std::filesystem::path> files,
                          const ImportSettings& settings) {
  nlohmann::json names = nlohmann::json::array();
  for (const std::filesystem::path& file : files) names.push_back(file.string());
  const nlohmann::json document = {
      {"files", names},
      {"readers", nlohmann::json::parse(settings_to_json(settings.readers))},
      {"allow_duplicates", settings.allow_duplicates}};
  return document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Refuses a scan whose data the project, or this import, already holds.
void refuse_duplicate(const Project& project, const EncodedScan& scan,
                      const std::filesystem::path& file, std::set<std::int64_t>& digests) {
  const auto twin = project.scan_with_content(scan.content_digest);
  const bool repeated = !digests.insert(scan.content_digest).second;
  if (!twin && !repeated) return;
  core::FilePosition position;
  position.detail = "scan \"" + scan.metadata.name + "\"";
  throw core::InputError(
      file.string(), position,
      (twin ? "is already in the project as scan " + std::to_string(*twin)
            : std::string("appears twice in this import")) +
          "; importing it again would add a twin (--allow-duplicate imports it anyway)");
}

}  // namespace

ImportResult import_scans(Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  ImportResult result;
  // One part per scan: a file of many large scans never sits in memory
  // whole, and the write lock is held only while a scan's rows are written
  // (compression, most of the work, happens before).
  Project::LongCommand command = project.begin_long_command(kStage, settings_json(files, settings));
  result.command_id = command.command_id();
  std::set<std::int64_t> digests;  // of the scans of this import
  for (std::size_t f = 0; f < files.size(); ++f) {
    progress.throw_if_cancelled(kStage);
    const auto on_scan = [&](acquisition::ImportedScan&& imported) {
      const EncodedScan encoded = encode_scan(imported.scan);
      if (!settings.allow_duplicates) refuse_duplicate(project, encoded, files[f], digests);
      progress.throw_if_cancelled(kStage);
      Project::Edit part = command.part();
      const std::int64_t id = project.insert_scan(part, encoded);
      project.put_scan_source(part, id, imported.source);
      for (const acquisition::ScanImage& image : imported.images)
        project.insert_image(part, id, imported.scan.T_world_scan, image);
      part.commit_part();
      result.scan_ids.push_back(id);
      result.unplaced_points += imported.source.unplaced_points;
      result.images += imported.images.size();
    };
    const auto on_loose_image = [&](acquisition::ScanImage&& image) {
      Project::Edit part = command.part();
      project.insert_image(part, std::nullopt, Eigen::Isometry3d::Identity(), image);
      part.commit_part();
      ++result.images;
    };
    acquisition::read_scan_file(files[f], settings.readers, on_scan, on_loose_image);
    progress.update({kStage, f + 1, files.size(), files[f].filename().string()});
  }
  progress.throw_if_cancelled(kStage);
  // New scans can sample the merged surfaces more finely: the earlier
  // merge's keep masks no longer hold.
  Project::Edit finish = command.finish();
  for (const StoredScanSummary& stored : project.scans()) {
    project.remove_layer(finish, stored.id, layer::kKeep);
  }
  finish.commit(nlohmann::json{{"scans", result.scan_ids}}.dump());
  result.seconds = core::seconds_since(start);
  return result;
}

ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress) {
  std::error_code error;
  if (!std::filesystem::exists(std::filesystem::symlink_status(project_path, error))) {
    // A new project is filled as a draft and appears only once the import is
    // done: a refused import leaves nothing, and no other process ever sees
    // it half made.
    Project::Draft draft = Project::create_draft(project_path);
    ImportResult result = import_scans(draft.project(), files, settings, progress);
    if (draft.publish()) {
      result.created_project = true;
      return result;
    }
    // Another process created the project meanwhile: import into that one.
  }
  Project project = Project::open(project_path);
  return import_scans(project, files, settings, progress);
}

}  // namespace scanbench::modeling

#include "modeling/import_scans.hpp"

#include <chrono>
#include <nlohmann/json.hpp>

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
      {"files", names}, {"readers", nlohmann::json::parse(settings_to_json(settings.readers))}};
  return document.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

ImportResult import_scans(Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  // Compression is most of the work: done before the write lock is taken.
  std::vector<EncodedScan> encoded;
  for (std::size_t f = 0; f < files.size(); ++f) {
    progress.throw_if_cancelled(kStage);
    acquisition::read_scan_file(files[f], settings.readers, [&](acquisition::Scan&& scan) {
      encoded.push_back(encode_scan(scan));
    });
    progress.update({kStage, f + 1, files.size(), files[f].filename().string()});
  }
  progress.throw_if_cancelled(kStage);

  ImportResult result;
  Project::Edit edit = project.begin_command(kStage, settings_json(files, settings));
  result.command_id = edit.command_id();
  for (const EncodedScan& scan : encoded)
    result.scan_ids.push_back(project.insert_scan(edit, scan));
  edit.commit(nlohmann::json{{"scans", result.scan_ids}}.dump());
  result.seconds = core::seconds_since(start);
  return result;
}

ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress) {
  const bool existed = std::filesystem::exists(project_path);
  // Only a project this call created is removed on failure: if another
  // process creates the file first, create() refuses and nothing is removed.
  bool created = false;
  try {
    Project project = existed ? Project::open(project_path) : Project::create(project_path);
    created = !existed;
    ImportResult result = import_scans(project, files, settings, progress);
    result.created_project = created;
    return result;
  } catch (...) {
    if (created) remove_project_files(project_path);
    throw;
  }
}

}  // namespace scanbench::modeling

#include "modeling/import_scans.hpp"

#include <chrono>

#include "core/timing.hpp"
#include "modeling/project.hpp"

namespace scanbench::modeling {
namespace {

ImportResult import_into(Project& project, std::span<const std::filesystem::path> files,
                         const ImportSettings& settings) {
  ImportResult result;
  Project::Transaction transaction = project.begin();
  for (std::size_t f = 0; f < files.size(); ++f) {
    acquisition::read_scan_file(files[f], settings.readers, [&](acquisition::Scan&& scan) {
      result.scan_ids.push_back(project.insert_scan(scan));
      if (settings.on_scan_stored) {
        settings.on_scan_stored({f, files.size(), scan.name, result.scan_ids.size()});
      }
    });
  }
  transaction.commit();
  return result;
}

}  // namespace

ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const bool existed = std::filesystem::exists(project_path);
  // Only a project this call created is removed on failure: if another
  // process creates the file first, create() refuses and nothing is removed.
  bool created = false;
  ImportResult result;
  try {
    Project project = existed ? Project::open(project_path) : Project::create(project_path);
    created = !existed;
    result = import_into(project, files, settings);
  } catch (...) {
    if (created) remove_project_files(project_path);
    throw;
  }
  result.created_project = created;
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::modeling

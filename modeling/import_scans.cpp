#include "modeling/import_scans.hpp"

#include <chrono>

#include "modeling/project.hpp"

namespace scanbench::modeling {
namespace {

// A project this import created holds nothing worth keeping after a failure.
void remove_project_files(const std::filesystem::path& project_path) {
  std::error_code ignored;
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::filesystem::remove(project_path.string() + suffix, ignored);
  }
}

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
  ImportResult result;
  try {
    Project project = existed ? Project::open(project_path) : Project::create(project_path);
    result = import_into(project, files, settings);
  } catch (...) {
    if (!existed) remove_project_files(project_path);
    throw;
  }
  result.created_project = !existed;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scanbench::modeling

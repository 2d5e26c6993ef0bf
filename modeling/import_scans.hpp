// The import stage: raw scan files into a project as the command "import",
// all or nothing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "acquisition/scan_files.hpp"
#include "core/progress.hpp"
#include "modeling/project.hpp"

namespace scanbench::modeling {

struct ImportSettings {
  acquisition::ScanFileSettings readers;
};

struct ImportResult {
  std::int64_t command_id = 0;         // the journal entry
  std::vector<std::int64_t> scan_ids;  // new ids, in file order
  bool created_project = false;        // import_scan_files only
  double seconds = 0.0;
};

// Reads and encodes every scan of `files` (one unit of `progress` per
// file), then stores them all as one command. On any error (core::InputError
// from a reader, a write failure) or cancellation nothing is stored.
ImportResult import_scans(Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress);

// import_scans into the project at `project_path`, which is created when it
// does not exist; a project this call created is removed again when the
// import fails.
ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress);

}  // namespace scanbench::modeling

// The import stage: raw scan files into a project, all or nothing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "acquisition/scan_files.hpp"

namespace scanbench::modeling {

struct ImportProgress {
  std::size_t file_index = 0;  // 0-based index into the file list
  std::size_t file_count = 0;
  std::string scan_name;         // the scan just stored
  std::size_t scans_stored = 0;  // so far in this import
};

struct ImportSettings {
  acquisition::ScanFileSettings readers;
  // Called after each scan is stored (inside the transaction, so a kill here
  // must leave the project unchanged). Optional.
  std::function<void(const ImportProgress&)> on_scan_stored;
};

struct ImportResult {
  std::vector<std::int64_t> scan_ids;  // new ids, in file order
  bool created_project = false;
  double seconds = 0.0;
};

// Imports every scan of `files` into the project at `project_path` in one
// transaction. Creates the project when it does not exist. On any error
// (InputError from a reader or the project, or a write failure) nothing is
// stored: the transaction rolls back, and a project this call created is
// removed again, then the error propagates.
ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings = {});

}  // namespace scanbench::modeling

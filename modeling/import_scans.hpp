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
  // A scan whose data (range and validity) is already in the project, or
  // earlier in the same import, is refused unless this is set: importing a
  // file twice by mistake would add a silent twin.
  bool allow_duplicates = false;
};

struct ImportResult {
  std::int64_t command_id = 0;         // the journal entry
  std::vector<std::int64_t> scan_ids;  // new ids, in file order
  std::size_t images = 0;              // stored with the scans (E57 images2D)
  // Records the grids could not place (acquisition::ScanSource), all scans.
  std::uint64_t unplaced_points = 0;
  bool created_project = false;  // import_scan_files only
  double seconds = 0.0;
};

// Stores every scan of `files` as one command (one unit of `progress` per
// file), written scan by scan (Project::LongCommand), so memory holds one
// scan at a time. The merge's keep masks of the scans already there are
// removed with it: new scans may sample their surfaces more finely. On any
// error (core::InputError from a reader or for a duplicate, a write
// failure) or cancellation nothing becomes visible, and what was written is
// removed.
ImportResult import_scans(Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress);

// import_scans into the project at `project_path`. When it does not exist,
// the import fills a new project under a temporary name, which takes the
// name only when the import is done (Project::Draft): a failed import leaves
// no file, and when another process creates the project meanwhile, the scans
// go into that one.
ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress);

}  // namespace scanbench::modeling

// The import stage: raw scan files into a project as the command "import",
// all or nothing.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "acquisition/formats/scan_files.hpp"
#include "core/progress.hpp"
#include "core/spill_file.hpp"
#include "modeling/store/project.hpp"

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
  // The scans whose points come back farther than 0.1 mm from the file's
  // values (acquisition::kPromisedRoundTripM): the file, the scan's name and
  // its round_trip_error_m. Imported all the same; `import` says so.
  struct RoundTrip {
    std::filesystem::path file;
    std::string scan;
    double error_m = 0.0;
  };
  std::vector<RoundTrip> beyond_promise;
  bool created_project = false;  // import_scan_files only
  double seconds = 0.0;
};

class LayerSpill;  // import_command.cpp

// The files of an import, each read whole and checked by its reader, and
// the scans' digests (duplicates), before the project is opened for
// writing: a refused file never writes to the project. The compressed
// channels of the scans the check read are kept in an unnamed file in the
// temporary folder (on the disk unless TMPDIR names a memory file system),
// not in memory (where that file cannot be made or fills up, in memory as
// below), and stored from there, so the check holds one scan at a time
// however many files it reads. The images are kept in memory while
// they fit a quarter of the available memory; the files beyond are read
// again when stored (what such a file spilled stays in the temporary file
// until the import ends).
struct CheckedImport {
  struct Scan {
    std::string name;
    // The scan's metadata, its layers' blobs in `spill` (at spilled[k] for
    // layer k); none when the file is read again.
    std::optional<store::EncodedScan> encoded;
    using Place = core::SpillFile::Extent;
    std::vector<Place> spilled;
    std::int64_t digest = 0;                    // EncodedScan::content_digest
    acquisition::ScanSource source;
    std::vector<acquisition::ScanImage> images;  // kept ones only
  };
  struct File {
    std::filesystem::path path;
    bool kept = false;  // its scans and loose images are held here
    std::vector<Scan> scans;
    std::vector<acquisition::ScanImage> loose_images;
  };
  std::vector<File> files;
  // Shared: CheckedImport is moved around where LayerSpill is incomplete.
  std::shared_ptr<LayerSpill> spill;
};

// Reads and checks every file (one unit of `progress` per file, of two per
// file in all): throws core::InputError naming the file and the position
// (see the format's reader), or for a scan that appears twice in `files`
// unless settings.allow_duplicates; core::Cancelled when cancelled.
CheckedImport check_scan_files(std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress);

// Stores the checked scans as one command, written scan by scan
// (Project::LongCommand), so memory holds one scan at a time beyond what
// the check kept. A scan the project already holds is refused
// (core::InputError) before anything is written, unless
// settings.allow_duplicates. The merge's keep masks of the scans already
// there are removed with it: new scans may sample their surfaces more
// finely. On any error (a file that changed since its check, a write
// failure) or cancellation nothing becomes visible, and what was written is
// removed.
ImportResult store_checked_scans(store::Project& project, const CheckedImport& checked,
                                 const ImportSettings& settings, core::Progress& progress);

// check_scan_files, then store_checked_scans.
ImportResult import_scans(store::Project& project, std::span<const std::filesystem::path> files,
                          const ImportSettings& settings, core::Progress& progress);

// import_scans into the project at `project_path`, which is opened (or
// created) only once every file passed its check. When it does not exist,
// the import fills a new project under a temporary name, which takes the
// name only when the import is done (Project::Draft): a failed import leaves
// no file, and when another process creates the project meanwhile, the scans
// go into that one.
ImportResult import_scan_files(const std::filesystem::path& project_path,
                               std::span<const std::filesystem::path> files,
                               const ImportSettings& settings, core::Progress& progress);

}  // namespace scanbench::modeling

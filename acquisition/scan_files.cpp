#include "acquisition/scan_files.hpp"

#include <algorithm>
#include <cctype>

#include "acquisition/pcd_reader.hpp"
#include "acquisition/triplet_reader.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

ScanFileFormat scan_file_format(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".ptx") return ScanFileFormat::kPtx;
  if (extension == ".json") return ScanFileFormat::kTriplet;
  if (extension == ".pcd") return ScanFileFormat::kOrganizedPcd;
  throw core::InputError(path.string(), {},
                         "unknown scan file type \"" + extension +
                             "\" (expected .ptx, .pcd, or the .json sidecar of an image triplet)");
}

void read_scan_file(const std::filesystem::path& path, const ScanFileSettings& settings,
                    const std::function<void(Scan&&)>& on_scan) {
  switch (scan_file_format(path)) {
    case ScanFileFormat::kPtx:
      read_ptx(path, settings.ptx, on_scan);
      return;
    case ScanFileFormat::kTriplet:
      on_scan(read_triplet(path));
      return;
    case ScanFileFormat::kOrganizedPcd:
      on_scan(read_organized_pcd(path));
      return;
  }
}

}  // namespace scanbench::acquisition

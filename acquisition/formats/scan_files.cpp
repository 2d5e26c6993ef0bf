#include "acquisition/formats/scan_files.hpp"

#include <algorithm>

#include "acquisition/formats/e57/e57_reader.hpp"
#include "acquisition/formats/las_reader.hpp"
#include "acquisition/formats/pcd_reader.hpp"
#include "acquisition/formats/ply_reader.hpp"
#include "acquisition/formats/triplet_reader.hpp"
#include "core/errors.hpp"
#include "core/text.hpp"

namespace scanbench::acquisition {

ScanFileFormat scan_file_format(const std::filesystem::path& path) {
  const std::string extension = core::ascii_lower(path.extension().string());
  if (extension == ".ptx") return ScanFileFormat::kPtx;
  if (extension == ".json") return ScanFileFormat::kTriplet;
  if (extension == ".pcd") return ScanFileFormat::kPcd;
  if (extension == ".e57") return ScanFileFormat::kE57;
  if (extension == ".ply") return ScanFileFormat::kPly;
  if (extension == ".las") return ScanFileFormat::kLas;
  if (extension == ".laz") {
    throw core::InputError(path.string(), {},
                           "a LAZ (LASzip-compressed) file, which scanbench cannot read: Debian "
                           "does not package LASzip; decompress it to LAS first (laszip -i "
                           "FILE.laz -o FILE.las, or pdal translate)");
  }
  throw core::InputError(
      path.string(), {},
      "unknown scan file type \"" + extension +
          "\" (expected .ptx, .pcd, .e57, .ply, .las, or the .json sidecar of an image triplet)");
}

namespace {

// A scan of a format that holds nothing beside the grid.
ImportedScan plain(Scan&& scan, const char* format) {
  ImportedScan out;
  out.source.format = format;
  out.source.points_in_file = scan.pixel_count();  // every record, returns or not
  out.scan = std::move(scan);
  return out;
}

}  // namespace

void read_scan_file(const std::filesystem::path& path, const ScanFileSettings& settings,
                    const std::function<void(ImportedScan&&)>& deliver,
                    const std::function<void(ScanImage&&)>& on_loose_image) {
  const auto on_scan = [&deliver](ImportedScan&& imported) {
    imported.source.round_trip_error_m = imported.scan.import_round_trip_m;
    deliver(std::move(imported));
  };
  switch (scan_file_format(path)) {
    case ScanFileFormat::kPtx:
      read_ptx(path, settings.ptx,
               [&on_scan](Scan&& scan) { on_scan(plain(std::move(scan), "ptx")); });
      return;
    case ScanFileFormat::kTriplet: {
      std::vector<std::filesystem::path> images;
      ImportedScan scan = plain(read_triplet(path, &images), "triplet");
      scan.source.companion_files = std::move(images);
      on_scan(std::move(scan));
      return;
    }
    case ScanFileFormat::kPcd:
      for (ImportedScan& scan : read_pcd(path)) on_scan(std::move(scan));
      return;
    case ScanFileFormat::kE57:
      read_e57(path, on_scan, on_loose_image);
      return;
    case ScanFileFormat::kPly:
      for (ImportedScan& scan : read_ply(path)) on_scan(std::move(scan));
      return;
    case ScanFileFormat::kLas:
      for (ImportedScan& scan : read_las(path)) on_scan(std::move(scan));
      return;
  }
}

}  // namespace scanbench::acquisition

// One entry point for every raw-scan format: the format follows from the file
// name, and every reader streams its scans to a callback.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "acquisition/formats/ptx_reader.hpp"
#include "acquisition/scan.hpp"
#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

enum class ScanFileFormat { kPtx, kTriplet, kPcd, kE57, kPly, kLas };

// By extension, case-insensitive: .ptx, .json (an image triplet's sidecar),
// .pcd, .e57, .ply, .las (.laz is refused by name: no LASzip on Debian). Throws InputError naming the file for any other extension.
ScanFileFormat scan_file_format(const std::filesystem::path& path);

struct ScanFileSettings {
  PtxReadSettings ptx;
};

// Reads every scan of `path` and hands each, with its source description
// and images, to `on_scan`, in file order; images the file ties to no scan
// (E57 only) go to `on_loose_image` when given. Throws InputError (see the
// format's reader) on bad input; scans delivered before the error stay
// delivered.
void read_scan_file(const std::filesystem::path& path, const ScanFileSettings& settings,
                    const std::function<void(ImportedScan&&)>& on_scan,
                    const std::function<void(ScanImage&&)>& on_loose_image = {});

}  // namespace scanbench::acquisition

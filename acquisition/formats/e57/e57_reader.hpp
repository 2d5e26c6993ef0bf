// Reading ASTM E2807 (E57) files: every data3D entry becomes one scan, with
// the images2D the file ties to it.
//
// Structured scans (rowIndex and columnIndex fields) keep their grid, and a
// later return or a second record of a pixel already taken is counted in
// ScanSource::unplaced_points. A scan without them becomes a scattered scan
// (scan.hpp) that keeps every point with a return, in the file's order.
// Coordinates may be spherical or cartesian, fields Float, ScaledInteger or
// Integer of any width; the invalid-state fields mark pixels without a
// return. Intensity becomes [0, 1] and colour 8 bits through the scan's
// intensityLimits and colorLimits (else the fields' bounds). Georeferenced
// coordinates keep 0.1 mm through a local origin (local_origin.hpp).
#pragma once

#include <filesystem>
#include <functional>

#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Reads every scan of `path` and hands each to `on_scan` in file order;
// images tied to no scan go to `on_loose_image`. The checksum of every page
// read (the header, the XML and every section) is verified. Throws core::InputError naming the
// file, the page or element, and the problem for a bad signature or header, a checksum failure,
// malformed XML, a prototype without coordinates or not matching its data,
// indices outside the index bounds, or a truncated binary section.
void read_e57(const std::filesystem::path& path, const std::function<void(ImportedScan&&)>& on_scan,
              const std::function<void(ScanImage&&)>& on_loose_image);

}  // namespace scanbench::acquisition

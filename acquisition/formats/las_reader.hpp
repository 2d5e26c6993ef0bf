// Reading LAS 1.0–1.4 (ASPRS LASer, the exchange format of every survey
// tool) as an unstructured cloud: the points become a scattered scan
// (scan.hpp) that keeps every record, in the file's order.
//
// Point data formats 0–10 at their record length: x, y, z through the
// header's scales and offsets, intensity as
// [0, 1] (u16 / 65535, as our writer stores it), colour where the format
// has one (16-bit values scaled to 8 bits, unless every value of the file
// is below 256, as writers that store 8-bit colour leave them). The
// coordinate system is kept as ScanSource::coordinate_metadata: the OGC
// WKT record's text, or "EPSG:N" from a GeoTIFF key directory. The extra
// bytes fields NormalX, NormalY, NormalZ and Footprint (as our export
// writes them; other tools' spellings too) become ImportedScan::recorded,
// through each field's scale, offset and no-data value. LAZ
// (LASzip-compressed LAS) is refused by name: Debian does not package
// LASzip.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Reads `path` into one scan (format "las", points_in_file the records), or
// into tiles when it is too wide for one (point_cloud.hpp: scattered_scans).
// Throws core::InputError naming the file, the byte offset and the
// problem for a missing signature, a LAZ file, an unknown point format, a
// record shorter than its format, an extra bytes field of an unknown type
// or beyond the record, a header or records cut short.
std::vector<ImportedScan> read_las(const std::filesystem::path& path);

}  // namespace scanbench::acquisition

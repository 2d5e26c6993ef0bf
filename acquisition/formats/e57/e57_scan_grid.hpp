// One E57 data3D entry's point records made into a scan grid (see
// e57_reader.hpp for the mapping). Internal to acquisition/: e57_reader.cpp
// reads the section, this decodes it block by block, so that no field is
// ever held decoded whole.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include "acquisition/formats/e57/e57_document.hpp"
#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// The scans of `entry`, the `index`-th of the file at `path`, from its
// fields' bytestreams (one per prototype field, complete: read_e57_streams
// checked their lengths): its grid or scattered scan, and for a grid whose
// records with a return did not all find a pixel of their own (later
// returns, records repeating a pixel), a scattered scan of those, named
// NAME-unplaced, with the same pose. A scattered scan too wide for one is
// tiled (point_cloud.hpp: scattered_scans), NAME-1, NAME-2, … (or
// NAME-unplaced-1, …). Each part's GUID is the entry's with the same
// suffix as its name. Throws core::InputError
// naming the file and the record or element for a prototype without coordinates or with grid
// indices that are not Integer fields, indices outside the index bounds, or
// bounds of more than 16 pixels per record (or 2^30 pixels); throws
// core::MemoryShortage when the grid would not fit in memory.
std::vector<ImportedScan> scans_from_records(const std::filesystem::path& path,
                                             const E57ScanEntry& entry, std::size_t index,
                                             const std::vector<std::vector<std::byte>>& streams);

}  // namespace scanbench::acquisition

// Reading PLY (the polygon file format of scanning and photogrammetry tools)
// as an unstructured cloud: the vertices become a scattered scan (scan.hpp)
// that keeps every vertex with finite coordinates, in the file's order.
//
// ASCII and binary (little and big endian) bodies, every scalar type under
// both its names (char/int8 … double/float64). Read from the vertex element:
// x, y, z; red, green, blue (8-bit as they are, 16-bit scaled to 8, float
// [0, 1] scaled to 255; diffuse_red … accepted); intensity (also
// scalar_intensity, any case) as the file gives it; normals nx, ny, nz (or
// normal_x …) and the footprint radius (or footprint) as ImportedScan::
// recorded. Other properties (alpha, ours) and other elements (faces) are
// skipped, list properties before and in the vertex element by their counts.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Reads `path` into one scan (format "ply", points_in_file the vertex
// count), or into tiles when it is too wide for one (point_cloud.hpp:
// scattered_scans). Throws core::InputError naming the file, the line or byte
// offset, and the problem for a missing signature, an unknown format or
// type, a vertex element without x, y and z, a channel stored as a list,
// some but not all of a normal's components, a truncated body, or a value
// that is not a number (ASCII).
std::vector<ImportedScan> read_ply(const std::filesystem::path& path);

}  // namespace scanbench::acquisition

// Reading PCD files: organized point clouds (structured-light and
// depth-camera captures) into a Scan with per-pixel directions, unorganized
// ones (HEIGHT 1) into a scattered scan (scan.hpp), or its tiles when too
// wide for one (point_cloud.hpp). Our own reader of
// PCL's format (pcd_header.hpp); `scanbench bench io` compares it with PCL's.
#pragma once

#include <filesystem>
#include <vector>

#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Reads a PCD file (DATA ascii, binary or binary_compressed).
//
// Grid: rows = HEIGHT, columns = WIDTH; point i of the file is pixel
// (i / WIDTH, i % WIDTH). With HEIGHT 1 the cloud is unorganized: its
// points with a return become a scattered scan, in the file's order. Fields x, y, z (float, count
// 1) are required; an "rgb" or "rgba" field (4 bytes, packed 0x00RRGGBB as float or uint32) fills
// Scan::rgb and an "intensity" field (any numeric type) fills Scan::intensity,
// as the file gives it. Every other field is ignored.
//
// Per pixel: a point with a non-finite coordinate or exactly (0, 0, 0) is
// invalid (range 0, direction the zero vector); otherwise range_m = |p| [m]
// and direction = p / |p| in the sensor frame. T_world_scan is the VIEWPOINT
// (translation [m], unit quaternion w x y z), identity when absent. Points
// farther than 500 m from the sensor (a cloud stored in world coordinates)
// are measured from their centroid instead, which goes into T_world_scan
// (local_origin.hpp), so every point within 900 m of it keeps 0.1 mm of
// the file's value; an unorganized cloud spread wider is tiled
// (point_cloud.hpp: scattered_scans, STEM-1, STEM-2, …).
// One scan (or its tiles), source format "pcd", points_in_file the
// header's POINTS (a tile's: its points).
// name = file stem, scanner.name = "" (unknown), scanner.source_file = path
// (UTF-8), scanner.position_world = the VIEWPOINT translation.
//
// Throws InputError naming the file, the header line where it applies, and the
// problem, before loading any body, for: a missing or empty file, a header that
// is not a PCD header, no points, absurd dimensions (an organized cloud over
// 1,000,000 a side, HEIGHT over 1,000,000, or 2^31 points), WIDTH × HEIGHT ≠ POINTS,
// missing or non-float x/y/z, a badly sized rgb field, a body shorter than the
// header promises (truncated), a non-numeric or missing ASCII value, extra
// ASCII points, a value that does not fit its field's type, a damaged
// compressed body, and a VIEWPOINT that is non-finite, not numeric or whose
// quaternion is not unit (within kRigidTolerance).
std::vector<ImportedScan> read_pcd(const std::filesystem::path& path);

}  // namespace scanbench::acquisition

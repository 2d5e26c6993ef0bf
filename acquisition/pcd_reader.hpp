// Reading organized point clouds (structured-light and depth-camera captures)
// from PCD files into a Scan with per-pixel directions. This is the adapter
// behind which PCL stays: no other file includes PCL headers.
#pragma once

#include <filesystem>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Reads an organized PCD file (DATA ascii, binary or binary_compressed).
//
// Grid: rows = HEIGHT, columns = WIDTH; point i of the file is pixel
// (i / WIDTH, i % WIDTH). Fields x, y, z (float, count 1) are required; an
// "rgb" or "rgba" field (4 bytes, packed 0x00RRGGBB as float or uint32) fills
// Scan::rgb and an "intensity" field (any numeric type) fills Scan::intensity,
// as the file gives it. Every other field is ignored.
//
// Per pixel: a point with a non-finite coordinate or exactly (0, 0, 0) is
// invalid (range 0, direction the zero vector); otherwise range_m = |p| [m]
// and direction = p / |p| in the sensor frame. T_world_scan is the VIEWPOINT
// (translation [m], unit quaternion w x y z), identity when absent.
// name = file stem, scanner.name = "" (unknown), scanner.source_file = path
// (UTF-8), scanner.position_world = the VIEWPOINT translation.
//
// Throws InputError naming the file, the header line where it applies, and the
// problem, before loading any body, for: a missing or empty file, a header that
// is not a PCD header, HEIGHT ≤ 1 ("not an organized point cloud"), absurd
// dimensions (over 1,000,000 a side or 2^31 points), WIDTH × HEIGHT ≠ POINTS,
// missing or non-float x/y/z, a badly sized rgb field, a body shorter than the
// header promises (truncated), a non-numeric or missing ASCII value, extra
// ASCII points, and a VIEWPOINT that is non-finite, not numeric or whose
// quaternion is not unit (within kRigidTolerance). PCL's own failures and
// exceptions become InputError too; PCL's console output is silenced.
Scan read_organized_pcd(const std::filesystem::path& path);

}  // namespace scanbench::acquisition

// Leica PTX (ASCII) import.
//
// A PTX file holds one or more scans, each as:
//   columns                      (integer)
//   rows                         (integer)
//   sx sy sz                     registered scanner position [m]
//   ax ay az / bx by bz / cx cy cz   registered scanner axes
//   4 lines of 4 numbers         T_world_scan, column-major (the last line is
//                                the translation followed by 1)
//   columns · rows point lines   "x y z intensity" or "x y z intensity r g b",
//                                scan frame [m], column after column
// The pose stays a pose: points are kept in the scan frame, never baked into
// world coordinates. Where a file gives points already in world coordinates
// (an identity transform, points at 10^5–10^7 m), the scan frame moves to the
// header's scanner position or near the points (local_origin.hpp), so every
// coordinate keeps 0.1 mm (within a scanner's range: local_origin.hpp). Lines "0 0 0 ..." are
// missing returns; they stay in their grid position as invalid pixels. Point k of a scan is grid
// pixel (row k % rows, col k / rows).
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "acquisition/local_origin.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

struct PtxReadSettings {
  // The angle model and the local origin (local_origin.hpp): spherical when
  // the grid is a regular panorama around the file frame's origin or the
  // header's scanner position, otherwise per-pixel directions.
  LocalOriginSettings grid;
};

// Streams the scans of a PTX file to `on_scan` one at a time, in file order,
// so that a multi-scan file never sits in memory whole. Scan names are the
// file stem, then "<stem>-2", "<stem>-3" … for further scans.
// Throws InputError (file, line, byte offset, problem) on malformed input:
// empty or truncated files, non-integer or absurd dimensions, dimensions the
// remaining file cannot hold (checked before allocating), non-numeric, NaN or
// infinite fields, a point line with a field count other than 4 or 7 or
// differing from the scan's first line, colours outside 0–255, non-rigid or
// non-finite transforms. Scans already delivered to `on_scan` before the error
// stay delivered: callers that need all-or-nothing (the project import) wrap
// the call in a transaction.
void read_ptx(const std::filesystem::path& path, const PtxReadSettings& settings,
              const std::function<void(Scan&&)>& on_scan);

// Convenience: every scan of the file, in order.
std::vector<Scan> read_ptx(const std::filesystem::path& path, const PtxReadSettings& settings = {});

}  // namespace scanbench::acquisition

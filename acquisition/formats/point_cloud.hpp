// An unstructured cloud as a file holds it (LAS, PLY), on its way to
// becoming a scattered scan (scan.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "acquisition/scan.hpp"
#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// Readers reserve scattered_pixel_count(points) entries (three for rgb), so
// that the scan takes the vectors without copying them.
struct PointCloud {
  std::vector<Eigen::Vector3d> points;  // in the file's frame [m], its order
  std::vector<float> intensity;         // empty, or one per point
  std::vector<std::uint8_t> rgb;        // empty, or R, G, B per point
  // Recorded geometry (RecordedGeometry): empty, or one per point. Normals
  // in the file's frame, of any length (zero or not finite: none);
  // footprints as a radius [m] (not positive or not finite: none).
  std::vector<Eigen::Vector3f> normal;
  std::vector<float> footprint_m;
};

// Cubes a cloud too wide for one scan is split into [m]: no point of a
// cube lies farther than 693 m from its centroid, where float ranges and
// directions keep 0.1 mm.
inline constexpr double kCloudTileM = 400.0;

// The scattered scan of `cloud` (its points taken), named after the stem
// of `path`, with `path` as its source file, and the geometry the cloud
// recorded, its normals turned into the scan frame and made unit length.
// A cloud so wide that one scan would put a point more than 0.1 mm from
// its value in the file (kPromisedRoundTripM: spread over more than about
// a kilometre) becomes one scan per cube of kCloudTileM it touches instead,
// named STEM-1, STEM-2, … (the cubes in x, then y, then z order, each with
// its points in the file's order and points_in_file its point count), so
// that every point keeps 0.1 mm. Throws core::InputError naming `path`
// when the cloud has no point (a 0 × 0 scan is no scan). Asserts the
// channels are empty or one per point. The caller fills the rest of the
// sources.
std::vector<ImportedScan> scattered_scans(PointCloud&& cloud, const std::filesystem::path& path);

// Names the scans of one cloud: `name` when there is one, else NAME-1,
// NAME-2, … (scattered_scans' tiles).
void name_tiles(std::span<ImportedScan> tiles, const std::string& name);

}  // namespace scanbench::acquisition

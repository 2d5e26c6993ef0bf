// What a scan file holds beside the scan grid: the pictures taken with the
// scan (E57's images2D) and the file's own description of the scan. The
// readers deliver them with each scan; the project stores them, and the E57
// writer writes them back.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// How an image maps directions onto pixels (ASTM E2807 §8.4): a pinhole
// camera, a spherical panorama or a cylindrical one, or none (a visual
// reference, a picture only). The parameters are the file's, in metres and
// pixels; those a projection does not use stay 0.
enum class ImageProjection { kPinhole, kSpherical, kCylindrical, kVisualReference };

struct ScanImage {
  std::string name;  // UTF-8; may be empty
  std::string guid;  // the file's identifier of the image; may be empty
  ImageProjection projection = ImageProjection::kPinhole;
  int width = 0;              // [pixels]
  int height = 0;             // [pixels]
  double pixel_width = 0.0;   // [m] on the sensor (pinhole) or [rad] (spherical, cylindrical)
  double pixel_height = 0.0;  // as pixel_width
  double focal_length = 0.0;  // pinhole [m]
  double principal_x = 0.0;   // pinhole [pixels]
  double principal_y = 0.0;   // pinhole and cylindrical [pixels]
  double radius = 0.0;        // cylindrical [m]
  // The camera's pose in the world frame (E57 poses the image in the file's
  // coordinates, as scans).
  Eigen::Isometry3d T_world_image = Eigen::Isometry3d::Identity();
  std::string format;              // "jpeg" or "png"
  std::vector<std::uint8_t> data;  // the encoded image, as the file held it
};

// Where a source file was when it was imported: its absolute path and its
// identity on that machine (device and inode; 0 where it could not be
// told), so that no output replaces it, whatever link or rename leads there.
struct SourceFile {
  std::string path;  // UTF-8; empty when not recorded (imports before sources' files were)
  std::uint64_t device = 0;
  std::uint64_t inode = 0;
};

// The file at `path` as a SourceFile (its canonical absolute path).
SourceFile identify_source_file(const std::filesystem::path& path);

// True when `output` names `source`: the same absolute path, or an existing
// file that is the same file (device and inode) as the source was.
bool names_source_file(const std::filesystem::path& output, const SourceFile& source);

// The source file's description of a scan.
struct ScanSource {
  std::string format;  // "e57", "ptx", "triplet", "pcd", "las", "ply"
  std::string guid;    // E57: the data3D guid; else empty
  // E57: the file's coordinateMetadata (its coordinate reference system,
  // as the file words it: an EPSG code, WKT, …); else empty.
  std::string coordinate_metadata;
  // Records the file held for the scan (returns or not; for the grid
  // formats, rows × columns), and how many of them the grid could not
  // place: a structured scan's later returns and repeated indices, those
  // with a return kept in the scattered scan NAME-unplaced beside it (an
  // unstructured scan places every point: scan.hpp's scattered scans). A
  // part of a file's scan (NAME-unplaced, a tile of a cloud too wide for
  // one scan: point_cloud.hpp) counts the points it holds.
  std::uint64_t points_in_file = 0;
  std::uint64_t unplaced_points = 0;
  // The farthest any placed point lies from its value in the file [m]
  // (Scan::import_round_trip_m); 0 for grids of ranges and angles (image
  // triplets) and for projects imported before it was recorded.
  double round_trip_error_m = 0.0;
  // The files the reader read besides the one it was given (a triplet's
  // images), as it found them.
  std::vector<std::filesystem::path> companion_files;
  // The file and its companions where they were when imported: set by the
  // import (identify_source_files), not by the readers.
  std::vector<SourceFile> files;
};

// What every import promises of round_trip_error_m [m]: 0.1 mm, met unless
// a cloud spreads beyond float ranges' reach; `import` and `info` say so
// where it is not.
inline constexpr double kPromisedRoundTripM = 1e-4;

// Sets source.files: `path`, the file the scan was read from, and
// source.companion_files, identified (identify_source_file).
void identify_source_files(const std::filesystem::path& path, ScanSource& source);

// One scan as a reader delivers it.
struct ImportedScan {
  Scan scan;
  ScanSource source;
  std::vector<ScanImage> images;  // those the file ties to this scan
  RecordedGeometry recorded;      // what the file recorded of it (scattered scans)
};

// "pinhole", "spherical", "cylindrical" or "visual_reference".
const char* projection_name(ImageProjection projection);

}  // namespace scanbench::acquisition

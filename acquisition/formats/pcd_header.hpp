// The header of a PCD file (Point Cloud Library's format, versions 0.5–0.7):
// which fields a point has, how many points, the sensor pose and how the
// body is stored. Internal to the PCD reader.
//
//   FIELDS x y z rgb …      names          VERSION, comments (#): ignored
//   SIZE 4 4 4 4 …          bytes: 1 2 4 8 (default 4)
//   TYPE F F F U …          I, U or F (default F; F is 4 or 8 bytes)
//   COUNT 1 1 1 1 …         values per field (default 1)
//   WIDTH w / HEIGHT h      organized: h rows of w points
//   VIEWPOINT tx ty tz qw qx qy qz   sensor pose (default identity)
//   POINTS n                w · h
//   DATA ascii | binary | binary_compressed   the last header line
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "acquisition/formats/text_lines.hpp"

namespace scanbench::acquisition {

struct PcdField {
  std::string name;
  std::uint64_t size = 4;    // bytes per value
  char type = 'F';           // 'I', 'U' or 'F'
  std::uint64_t count = 1;   // values
  std::uint64_t offset = 0;  // first byte within a point (binary)
  std::uint64_t column = 0;  // first value within a point (ASCII)
};

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0;
  std::uint64_t height = 0;
  std::uint64_t points = 0;
  Eigen::Isometry3d viewpoint = Eigen::Isometry3d::Identity();
  PcdData data = PcdData::kAscii;
  std::uint64_t point_step = 0;        // bytes per point: Σ size · count
  std::uint64_t values_per_point = 0;  // ASCII values per point: Σ count
  std::uint64_t body_offset = 0;       // first byte after the DATA line
};

// Reads and checks the header; `reader` is left at the first body line.
// Throws core::InputError naming the file and line for: no DATA line (not a
// PCD file), an unknown header line, SIZE/TYPE/COUNT that are absurd or
// disagree with FIELDS in length, a float field that is not 4 or 8 bytes,
// missing POINTS, HEIGHT ≤ 1 (not organized), an empty cloud, more than
// 1,000,000 a side or 2^31 points, WIDTH × HEIGHT ≠ POINTS, and a VIEWPOINT
// that is short, not numeric, not finite or whose quaternion is not unit.
PcdHeader read_pcd_header(TextLineReader& reader);

// The field called `name`, or null.
const PcdField* find_field(const PcdHeader& header, std::string_view name);

}  // namespace scanbench::acquisition

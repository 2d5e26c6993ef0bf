// The XML section of an E57 file (ASTM E2807 §8) as the few structs
// scanbench reads and writes: the data3D scans with their point prototypes
// and the images2D pictures. Parsing checks every element it uses and names
// the element path in its errors.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/formats/e57/e57_bitpack.hpp"
#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

// A compressed vector of point records: where its section starts and its
// fields, in bytestream order.
struct E57PointsEntry {
  std::uint64_t file_offset = 0;  // physical offset of the section header
  std::uint64_t record_count = 0;
  std::vector<E57Field> fields;
  const E57Field* field(std::string_view name) const;
};

struct E57IndexBounds {
  std::int64_t row_minimum = 0, row_maximum = 0;
  std::int64_t column_minimum = 0, column_maximum = 0;
  std::int64_t return_minimum = 0, return_maximum = 0;
};

struct E57ScanEntry {
  std::string path;  // "/data3D/0", for messages
  std::string guid;
  std::string name;
  std::string description;
  std::string sensor_model;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // T_file_scan
  std::optional<E57IndexBounds> index_bounds;
  std::optional<std::pair<double, double>> intensity_limits;             // minimum, maximum
  std::optional<std::array<std::pair<double, double>, 3>> color_limits;  // red, green, blue
  E57PointsEntry points;
};

// An image with the position of its encoded bytes in the file.
struct E57ImageEntry {
  std::string path;  // "/images2D/0"
  std::string associated_scan_guid;
  ScanImage image;                // data left empty by the parser
  std::uint64_t blob_offset = 0;  // physical offset of the blob section header
  std::uint64_t blob_length = 0;  // bytes of the encoded image
};

struct E57Document {
  std::string guid;
  std::string coordinate_metadata;
  std::vector<E57ScanEntry> scans;
  std::vector<E57ImageEntry> images;
};

// Parses the XML section. Throws core::InputError naming `file`, the XML
// offset or the element path, and the problem, for malformed XML, a root
// that is not an E57 root, a missing or mistyped element, a prototype
// field of an unsupported type (String) or impossible bounds.
E57Document parse_e57_xml(std::string_view xml, const std::string& file);

// The XML section of `document`, with each scan's points and each image's
// blob at the offsets the entries give.
std::string write_e57_xml(const E57Document& document);

}  // namespace scanbench::acquisition

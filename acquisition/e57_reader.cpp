#include "acquisition/e57_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>

#include "acquisition/e57_compressed_vector.hpp"
#include "acquisition/e57_document.hpp"
#include "acquisition/e57_pages.hpp"
#include "acquisition/local_origin.hpp"
#include "acquisition/panorama_projection.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kHeaderBytes = 48;
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 30;

struct FileHeader {
  std::uint64_t physical_length = 0;
  std::uint64_t xml_offset = 0;
  std::uint64_t xml_length = 0;
};

[[noreturn]] void bad_header(const E57PageReader& file, std::uint64_t offset,
                             const std::string& problem) {
  core::FilePosition position;
  position.byte_offset = offset;
  position.detail = "file header";
  throw core::InputError(file.file_name(), position, problem);
}

FileHeader read_header(E57PageReader& file) {
  std::byte bytes[kHeaderBytes];
  file.read(0, bytes, "file header");
  if (std::memcmp(bytes, "ASTM-E57", 8) != 0) {
    bad_header(file, 0, "not an E57 file: the signature is not \"ASTM-E57\"");
  }
  std::uint32_t major = 0;
  std::memcpy(&major, bytes + 8, 4);
  FileHeader header;
  std::uint64_t page_size = 0;
  std::memcpy(&header.physical_length, bytes + 16, 8);
  std::memcpy(&header.xml_offset, bytes + 24, 8);
  std::memcpy(&header.xml_length, bytes + 32, 8);
  std::memcpy(&page_size, bytes + 40, 8);
  if (major != 1)
    bad_header(file, 8, "E57 major version " + std::to_string(major) + " (1 is read)");
  if (page_size != kE57PageSize) bad_header(file, 40, "page size is not 1024");
  if (header.physical_length != file.physical_length()) {
    bad_header(file, 16,
               "the header gives a length of " + std::to_string(header.physical_length) +
                   " bytes but the file has " + std::to_string(file.physical_length()) +
                   " (truncated or appended to)");
  }
  if (header.xml_length == 0 || header.xml_length > file.physical_length()) {
    bad_header(file, 32, "impossible XML section length");
  }
  return header;
}

// The decoded values of one field, or none when the prototype lacks it.
std::optional<std::vector<double>> decode(const E57PointsEntry& points,
                                          const std::vector<std::vector<std::byte>>& streams,
                                          std::string_view name) {
  for (std::size_t f = 0; f < points.fields.size(); ++f) {
    if (points.fields[f].name != name) continue;
    std::vector<double> values(points.record_count);
    const bool complete = e57_unpack(points.fields[f], streams[f], values);
    (void)complete;  // read_e57_streams checked every stream's length
    return values;
  }
  return std::nullopt;
}

// The bounds a field's values are scaled from: the scan's limits when it
// gives them, else the field's own bounds when finite, else `fallback`.
std::pair<double, double> value_bounds(const E57Field* field,
                                       const std::optional<std::pair<double, double>>& limits,
                                       std::pair<double, double> fallback) {
  if (limits && limits->second > limits->first) return *limits;
  if (field == nullptr) return fallback;
  if (field->type == E57FieldType::kFloat) {
    if (std::isfinite(field->float_minimum) && std::isfinite(field->float_maximum) &&
        field->float_maximum > field->float_minimum) {
      return {field->float_minimum, field->float_maximum};
    }
    return fallback;
  }
  const double lo = static_cast<double>(field->minimum) * field->scale + field->offset;
  const double hi = static_cast<double>(field->maximum) * field->scale + field->offset;
  if (std::abs(field->maximum) < (std::int64_t{1} << 53) &&
      std::abs(field->minimum) < (std::int64_t{1} << 53) && hi != lo) {
    return {std::min(lo, hi), std::max(lo, hi)};
  }
  return fallback;
}

// The records of one scan, decoded: positions in the scan's file frame,
// what is valid, and the optional channels.
struct Records {
  std::vector<Eigen::Vector3d> points;  // meaningful where state == 0
  std::vector<std::uint8_t> state;      // 0 valid, 1 direction only, 2 nothing
  std::optional<std::vector<double>> row, column, returns, intensity;
  std::array<std::optional<std::vector<double>>, 3> color;
};

Records decode_records(E57PageReader& file, const E57ScanEntry& entry) {
  const E57PointsEntry& points = entry.points;
  const auto streams = read_e57_streams(file, points, "points of " + entry.path);
  Records records;
  const std::size_t n = points.record_count;
  records.points.resize(n);
  records.state.assign(n, 0);
  const auto r = decode(points, streams, "sphericalRange");
  const auto az = decode(points, streams, "sphericalAzimuth");
  const auto el = decode(points, streams, "sphericalElevation");
  const auto x = decode(points, streams, "cartesianX");
  const auto y = decode(points, streams, "cartesianY");
  const auto z = decode(points, streams, "cartesianZ");
  const bool spherical = r && az && el;
  if (!spherical && !(x && y && z)) {
    core::FilePosition position;
    position.detail = "XML element " + entry.path + "/points/prototype";
    throw core::InputError(file.file_name(), position,
                           "has neither cartesianX/Y/Z nor sphericalRange/Azimuth/Elevation");
  }
  const auto invalid =
      decode(points, streams, spherical ? "sphericalInvalidState" : "cartesianInvalidState");
  for (std::size_t i = 0; i < n; ++i) {
    if (spherical) {
      const double ce = std::cos((*el)[i]);
      records.points[i] = (*r)[i] * Eigen::Vector3d(ce * std::cos((*az)[i]),
                                                    ce * std::sin((*az)[i]), std::sin((*el)[i]));
    } else {
      records.points[i] = Eigen::Vector3d((*x)[i], (*y)[i], (*z)[i]);
    }
    const int state = invalid ? static_cast<int>((*invalid)[i]) : 0;
    records.state[i] = static_cast<std::uint8_t>(std::clamp(state, 0, 2));
    if (records.state[i] == 0 && !(records.points[i].allFinite() && records.points[i].norm() > 0)) {
      records.state[i] = 2;
    }
  }
  records.row = decode(points, streams, "rowIndex");
  records.column = decode(points, streams, "columnIndex");
  records.returns = decode(points, streams, "returnIndex");
  records.intensity = decode(points, streams, "intensity");
  records.color = {decode(points, streams, "colorRed"), decode(points, streams, "colorGreen"),
                   decode(points, streams, "colorBlue")};
  return records;
}

[[noreturn]] void bad_index(const std::string& file, const E57ScanEntry& entry, std::size_t record,
                            const std::string& problem) {
  core::FilePosition position;
  position.detail = "record " + std::to_string(record) + " of " + entry.path;
  throw core::InputError(file, position, problem);
}

// Pixel of every record (or none), and the grid size.
struct Placement {
  int rows = 0;
  int columns = 0;
  std::vector<std::int64_t> pixel;  // per record; -1: not placed
  std::uint64_t unplaced = 0;
};

Placement place_structured(const std::string& file, const E57ScanEntry& entry,
                           const Records& records) {
  const auto& rows = *records.row;
  const auto& cols = *records.column;
  std::int64_t row_min = 0, row_max = -1, col_min = 0, col_max = -1;
  if (entry.index_bounds) {
    row_min = entry.index_bounds->row_minimum;
    row_max = entry.index_bounds->row_maximum;
    col_min = entry.index_bounds->column_minimum;
    col_max = entry.index_bounds->column_maximum;
  } else if (!rows.empty()) {
    row_min = static_cast<std::int64_t>(*std::min_element(rows.begin(), rows.end()));
    row_max = static_cast<std::int64_t>(*std::max_element(rows.begin(), rows.end()));
    col_min = static_cast<std::int64_t>(*std::min_element(cols.begin(), cols.end()));
    col_max = static_cast<std::int64_t>(*std::max_element(cols.begin(), cols.end()));
  }
  Placement placement;
  const std::uint64_t height =
      row_max >= row_min ? static_cast<std::uint64_t>(row_max - row_min + 1) : 0;
  const std::uint64_t width =
      col_max >= col_min ? static_cast<std::uint64_t>(col_max - col_min + 1) : 0;
  if (height * width > kMaxPixels || height > (1u << 30) || width > (1u << 30)) {
    bad_index(file, entry, 0,
              "has index bounds of " + std::to_string(height) + " × " + std::to_string(width) +
                  " pixels, more than scanbench holds");
  }
  placement.rows = static_cast<int>(height);
  placement.columns = static_cast<int>(width);
  placement.pixel.assign(rows.size(), -1);
  std::vector<std::uint8_t> taken(height * width, 0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto r = static_cast<std::int64_t>(rows[i]) - row_min;
    const auto c = static_cast<std::int64_t>(cols[i]) - col_min;
    if (r < 0 || c < 0 || r >= static_cast<std::int64_t>(height) ||
        c >= static_cast<std::int64_t>(width)) {
      bad_index(file, entry, i,
                "has row " + std::to_string(static_cast<std::int64_t>(rows[i])) + ", column " +
                    std::to_string(static_cast<std::int64_t>(cols[i])) +
                    " outside the scan's index bounds");
    }
    const std::int64_t p = r * static_cast<std::int64_t>(width) + c;
    const bool later_return = records.returns && (*records.returns)[i] > 0;
    if (later_return || taken[p]) {
      ++placement.unplaced;
      continue;
    }
    taken[p] = 1;
    placement.pixel[i] = p;
  }
  return placement;
}

Placement place_unstructured(const Records& records) {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < records.points.size(); ++i) {
    if (records.state[i] != 0) continue;
    points.push_back(records.points[i]);
    ids.push_back(i);
  }
  const PanoramaProjection projection = project_to_panorama(points);
  Placement placement;
  placement.rows = projection.rows;
  placement.columns = projection.columns;
  placement.pixel.assign(records.points.size(), -1);
  for (std::size_t k = 0; k < ids.size(); ++k) placement.pixel[ids[k]] = projection.pixel[k];
  placement.unplaced = projection.collisions;
  return placement;
}

// 8-bit colour of value v between lo and hi.
std::uint8_t to_byte(double v, std::pair<double, double> bounds) {
  const double t = (v - bounds.first) / (bounds.second - bounds.first);
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
}

ImportedScan build_scan(const std::filesystem::path& path, const E57ScanEntry& entry,
                        std::size_t index, const Records& records, const Placement& placement) {
  const E57PointsEntry& fields = entry.points;
  const bool with_intensity = records.intensity.has_value();
  const bool with_color = records.color[0] && records.color[1] && records.color[2];
  ImportedScan out;
  Scan& scan = out.scan;
  scan = make_empty_scan(placement.rows, placement.columns, with_intensity, with_color);
  scan.name = entry.name.empty() ? path.stem().string() + "#" + std::to_string(index) : entry.name;
  scan.scanner.name = entry.sensor_model;
  scan.scanner.source_file = path.string();
  scan.scanner.position_world = entry.pose.translation();
  scan.T_world_scan = entry.pose;
  std::vector<Eigen::Vector3d> points_file(scan.pixel_count(), Eigen::Vector3d::Zero());
  const auto intensity_bounds =
      value_bounds(fields.field("intensity"), entry.intensity_limits, {0.0, 1.0});
  const char* color_names[3] = {"colorRed", "colorGreen", "colorBlue"};
  std::array<std::pair<double, double>, 3> color_bounds;
  for (int c = 0; c < 3; ++c) {
    std::optional<std::pair<double, double>> limits;
    if (entry.color_limits) limits = (*entry.color_limits)[c];
    color_bounds[c] = value_bounds(fields.field(color_names[c]), limits, {0.0, 255.0});
  }
  for (std::size_t i = 0; i < placement.pixel.size(); ++i) {
    const std::int64_t p = placement.pixel[i];
    if (p < 0) continue;
    scan.valid[p] = records.state[i] == 0;
    points_file[p] = records.points[i];
    if (with_intensity) {
      const double t = ((*records.intensity)[i] - intensity_bounds.first) /
                       (intensity_bounds.second - intensity_bounds.first);
      scan.intensity[p] = static_cast<float>(std::clamp(t, 0.0, 1.0));
    }
    if (with_color) {
      for (int c = 0; c < 3; ++c)
        scan.rgb[3 * p + c] = to_byte((*records.color[c])[i], color_bounds[c]);
    }
  }
  set_grid_from_points(scan, points_file, std::nullopt);
  out.source.format = "e57";
  out.source.guid = entry.guid;
  out.source.points_in_file = fields.record_count;
  out.source.unplaced_points = placement.unplaced;
  return out;
}

ScanImage read_image(E57PageReader& file, const E57ImageEntry& entry) {
  ScanImage image = entry.image;
  const std::string what = "image blob of " + entry.path;
  std::byte header[16];
  file.read(entry.blob_offset, header, what);
  std::uint64_t section_bytes = 0;
  std::memcpy(&section_bytes, header + 8, 8);
  if (std::to_integer<int>(header[0]) != 0 || section_bytes < 16 + entry.blob_length) {
    core::FilePosition position;
    position.byte_offset = entry.blob_offset;
    position.detail = entry.path;
    throw core::InputError(
        file.file_name(), position,
        "is not a blob section of " + std::to_string(entry.blob_length) + " bytes");
  }
  image.data.resize(entry.blob_length);
  file.read(e57_advance(entry.blob_offset, 16), std::as_writable_bytes(std::span(image.data)),
            what);
  return image;
}

}  // namespace

void read_e57(const std::filesystem::path& path, const std::function<void(ImportedScan&&)>& on_scan,
              const std::function<void(ScanImage&&)>& on_loose_image) {
  E57PageReader file(path);
  const FileHeader header = read_header(file);
  std::string xml(header.xml_length, '\0');
  file.read(header.xml_offset, std::as_writable_bytes(std::span(xml)), "XML section");
  const E57Document document = parse_e57_xml(xml, file.file_name());
  std::vector<bool> image_taken(document.images.size(), false);
  for (std::size_t k = 0; k < document.scans.size(); ++k) {
    const E57ScanEntry& entry = document.scans[k];
    const Records records = decode_records(file, entry);
    const bool structured = records.row && records.column;
    const Placement placement = structured ? place_structured(file.file_name(), entry, records)
                                           : place_unstructured(records);
    ImportedScan scan = build_scan(path, entry, k, records, placement);
    for (std::size_t i = 0; i < document.images.size(); ++i) {
      if (entry.guid.empty() || document.images[i].associated_scan_guid != entry.guid) continue;
      scan.images.push_back(read_image(file, document.images[i]));
      image_taken[i] = true;
    }
    on_scan(std::move(scan));
  }
  for (std::size_t i = 0; i < document.images.size(); ++i) {
    if (!image_taken[i] && on_loose_image) on_loose_image(read_image(file, document.images[i]));
  }
}

}  // namespace scanbench::acquisition

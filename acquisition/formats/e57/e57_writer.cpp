#include "acquisition/formats/e57/e57_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <memory>
#include <numbers>
#include <random>
#include <set>

#include "acquisition/formats/e57/e57_compressed_vector.hpp"
#include "acquisition/formats/e57/e57_document.hpp"
#include "acquisition/formats/e57/e57_pages.hpp"
#include "acquisition/formats/output_file.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr double kRangeScaleM = 1e-4;  // 0.1 mm
constexpr double kMaxRangeM = 4e5;

E57Field integer_field(const char* name, std::int64_t minimum, std::int64_t maximum) {
  E57Field field;
  field.name = name;
  field.type = E57FieldType::kInteger;
  field.minimum = minimum;
  field.maximum = maximum;
  return field;
}

E57Field float_field(const char* name, bool single, double minimum, double maximum) {
  E57Field field;
  field.name = name;
  field.type = E57FieldType::kFloat;
  field.single_precision = single;
  field.float_minimum = minimum;
  field.float_maximum = maximum;
  return field;
}

// The fields of a scan's records, in the order record_values fills them.
std::vector<E57Field> scan_fields(const Scan& scan, double max_range_m) {
  E57Field range;
  range.name = "sphericalRange";
  range.type = E57FieldType::kScaledInteger;
  range.scale = kRangeScaleM;
  range.minimum = 0;
  range.maximum = static_cast<std::int64_t>(std::ceil(max_range_m / kRangeScaleM)) + 1;
  std::vector<E57Field> fields = {
      range, float_field("sphericalAzimuth", false, -std::numbers::pi, std::numbers::pi),
      float_field("sphericalElevation", false, -std::numbers::pi / 2, std::numbers::pi / 2)};
  if (!scan.is_scattered()) {
    fields.push_back(integer_field("rowIndex", 0, std::max(scan.rows - 1, 0)));
    fields.push_back(integer_field("columnIndex", 0, std::max(scan.columns - 1, 0)));
  }
  fields.push_back(integer_field("sphericalInvalidState", 0, 2));
  if (scan.has_intensity()) fields.push_back(float_field("intensity", true, 0.0, 1.0));
  if (scan.has_color()) {
    for (const char* name : {"colorRed", "colorGreen", "colorBlue"}) {
      fields.push_back(integer_field(name, 0, 255));
    }
  }
  return fields;
}

// Azimuth and elevation of a pixel's direction; none when it is unknown.
bool pixel_angles(const Scan& scan, int row, int col, double& azimuth, double& elevation) {
  if (const auto* angles = std::get_if<SphericalAngles>(&scan.angles)) {
    // Within [−π, π], as the field's bounds say.
    azimuth = std::remainder(angles->azimuth(col), 2.0 * std::numbers::pi);
    elevation = angles->elevation(row);
    return true;
  }
  const Eigen::Vector3d d = direction_precise(scan, row, col);
  if (!(d.squaredNorm() > 0.5)) return false;
  azimuth = std::atan2(d.y(), d.x());
  elevation = std::asin(std::clamp(d.z(), -1.0, 1.0));
  return true;
}

bool written_as_valid(const E57ScanOutput& output, std::size_t p) {
  return output.scan->valid[p] && (output.keep == nullptr || (*output.keep)[p]);
}

// The pixels a scan's records hold, in order: every pixel of a grid (the
// reader gets the grid back whole), the written points of a scattered scan.
std::vector<std::size_t> record_pixels(const E57ScanOutput& output) {
  std::vector<std::size_t> pixels;
  for (std::size_t p = 0; p < output.scan->pixel_count(); ++p) {
    if (!output.scan->is_scattered() || written_as_valid(output, p)) pixels.push_back(p);
  }
  return pixels;
}

E57RecordSource record_values(const E57ScanOutput& output,
                              std::shared_ptr<const std::vector<std::size_t>> pixels) {
  return [&output, pixels](std::uint64_t first, std::uint64_t count,
                           std::vector<std::vector<double>>& columns) {
    const Scan& scan = *output.scan;
    for (std::uint64_t k = 0; k < count; ++k) {
      const std::size_t p = (*pixels)[first + k];
      const int row = static_cast<int>(p / scan.columns);
      const int col = static_cast<int>(p % scan.columns);
      double azimuth = 0.0, elevation = 0.0;
      const bool known = pixel_angles(scan, row, col, azimuth, elevation);
      const bool valid = written_as_valid(output, p);
      std::size_t f = 0;
      columns[f++][k] = valid ? scan.range_m[p] : 0.0;
      columns[f++][k] = azimuth;
      columns[f++][k] = elevation;
      if (!scan.is_scattered()) {
        columns[f++][k] = row;
        columns[f++][k] = col;
      }
      columns[f++][k] = valid ? 0.0 : known ? 1.0 : 2.0;
      if (scan.has_intensity()) columns[f++][k] = scan.intensity[p];
      if (scan.has_color()) {
        for (int c = 0; c < 3; ++c) columns[f++][k] = scan.rgb[3 * p + c];
      }
    }
  };
}

double max_range(const Scan& scan, const std::string& file) {
  double farthest = 0.0;
  for (std::size_t p = 0; p < scan.pixel_count(); ++p) {
    if (scan.valid[p]) farthest = std::max(farthest, static_cast<double>(scan.range_m[p]));
  }
  if (!(farthest <= kMaxRangeM)) {
    throw core::InputError(file, {{}, {}, "scan \"" + scan.name + "\""},
                           "has a range beyond 400 km, which E57 export does not hold");
  }
  return farthest;
}

// Writes `image`'s bytes as a blob section; returns the section's offset.
std::uint64_t write_blob(E57PageWriter& file, const ScanImage& image) {
  file.pad_to(4);
  const std::uint64_t section = file.physical_position();
  std::byte header[16] = {};
  const std::uint64_t length = (16 + image.data.size() + 3) / 4 * 4;
  std::memcpy(header + 8, &length, 8);  // section id 0 (blob) in byte 0
  file.write(header);
  file.write(std::as_bytes(std::span(image.data)));
  file.pad_to(4);
  return section;
}

E57ImageEntry image_entry(E57PageWriter& file, const ScanImage& image,
                          const std::string& scan_guid) {
  E57ImageEntry entry;
  entry.image = image;
  entry.image.data.clear();
  if (entry.image.guid.empty()) entry.image.guid = new_e57_guid();
  entry.associated_scan_guid = scan_guid;
  entry.blob_offset = write_blob(file, image);
  entry.blob_length = image.data.size();
  return entry;
}

E57ScanEntry scan_entry(E57PageWriter& file, const E57ScanOutput& output, const std::string& guid,
                        const std::string& name) {
  const Scan& scan = *output.scan;
  E57ScanEntry entry;
  entry.guid = guid;
  entry.name = scan.name;
  entry.sensor_model = scan.scanner.name;
  entry.pose = scan.T_world_scan;
  if (!scan.is_scattered()) {
    entry.index_bounds =
        E57IndexBounds{0, std::max(scan.rows - 1, 0), 0, std::max(scan.columns - 1, 0), 0, 0};
  }
  if (scan.has_intensity()) entry.intensity_limits = std::pair{0.0, 1.0};
  if (scan.has_color()) entry.color_limits = {{{0.0, 255.0}, {0.0, 255.0}, {0.0, 255.0}}};
  entry.points.fields = scan_fields(scan, max_range(scan, name));
  auto pixels = std::make_shared<const std::vector<std::size_t>>(record_pixels(output));
  entry.points.record_count = pixels->size();
  entry.points.file_offset = write_e57_points(file, entry.points.fields, entry.points.record_count,
                                              record_values(output, pixels));
  return entry;
}

}  // namespace

std::string new_e57_guid() {
  // Seeded with 256 bits: GUIDs of different runs must not collide.
  static thread_local std::mt19937_64 generator = [] {
    std::random_device device;
    std::seed_seq seeds{device(), device(), device(), device(),
                        device(), device(), device(), device()};
    return std::mt19937_64(seeds);
  }();
  const std::uint64_t a = generator();
  const std::uint64_t b = generator();
  return fmt::format("{{{:08x}-{:04x}-4{:03x}-{:04x}-{:012x}}}", a >> 32, (a >> 16) & 0xFFFF,
                     a & 0xFFF, 0x8000 | ((b >> 48) & 0x3FFF), b & 0xFFFFFFFFFFFF);
}

std::string e57_guid_from(std::string_view identity) {
  const auto fnv1a = [&](std::uint64_t hash) {
    for (const char c : identity) {
      hash ^= static_cast<unsigned char>(c);
      hash *= 0x100000001b3ULL;
    }
    return hash;
  };
  const std::uint64_t a = fnv1a(0xcbf29ce484222325ULL);  // FNV-1a's offset basis
  const std::uint64_t b = fnv1a(0x84222325cbf29ce4ULL ^ identity.size());
  return fmt::format("{{{:08x}-{:04x}-5{:03x}-{:04x}-{:012x}}}", a >> 32, (a >> 16) & 0xFFFF,
                     a & 0xFFF, 0x8000 | ((b >> 48) & 0x3FFF), b & 0xFFFFFFFFFFFF);
}

struct E57Writer::State {
  State(const std::filesystem::path& target, std::string coordinate_metadata)
      : path(target), out(target), file(out) {
    const std::vector<std::byte> header_space(48, std::byte{0});
    file.write(header_space);  // the header, written last
    document.guid = new_e57_guid();
    document.coordinate_metadata = std::move(coordinate_metadata);
  }

  std::filesystem::path path;
  OutputFile out;
  E57PageWriter file;
  E57Document document;
  std::set<std::string> guids;  // a guid names one scan of the file
};

E57Writer::E57Writer(const std::filesystem::path& path, std::string coordinate_metadata)
    : state_(std::make_unique<State>(path, std::move(coordinate_metadata))) {}

E57Writer::~E57Writer() = default;

void E57Writer::add(const E57ScanOutput& output) {
  State& s = *state_;
  std::string guid = output.guid;
  if (guid.empty() || !s.guids.insert(guid).second) {
    guid = new_e57_guid();
    s.guids.insert(guid);
  }
  E57ScanEntry entry = scan_entry(s.file, output, guid, s.path.string());
  for (const ScanImage& image : output.images) {
    s.document.images.push_back(image_entry(s.file, image, entry.guid));
  }
  s.document.scans.push_back(std::move(entry));
}

void E57Writer::commit(std::span<const ScanImage> loose_images) {
  State& s = *state_;
  E57PageWriter& file = s.file;
  for (const ScanImage& image : loose_images)
    s.document.images.push_back(image_entry(file, image, ""));
  file.pad_to(4);
  const std::uint64_t xml_offset = file.physical_position();
  std::string xml = write_e57_xml(s.document);
  xml.append((4 - xml.size() % 4) % 4, ' ');
  file.write(std::as_bytes(std::span(xml)));
  std::byte header[48] = {};
  std::memcpy(header, "ASTM-E57", 8);
  const std::uint32_t major = 1, minor = 0;
  std::memcpy(header + 8, &major, 4);
  std::memcpy(header + 12, &minor, 4);
  const std::uint64_t logical_end = file.logical_position();
  const std::uint64_t physical_length =
      (logical_end + kE57PagePayload - 1) / kE57PagePayload * kE57PageSize;
  const std::uint64_t xml_length = xml.size();
  const std::uint64_t page_size = kE57PageSize;
  std::memcpy(header + 16, &physical_length, 8);
  std::memcpy(header + 24, &xml_offset, 8);
  std::memcpy(header + 32, &xml_length, 8);
  std::memcpy(header + 40, &page_size, 8);
  [[maybe_unused]] const std::uint64_t written = file.finish(0, header);
  assert(written == physical_length);
  s.out.commit();
}

void write_e57(const std::filesystem::path& path, std::span<const E57ScanOutput> scans,
               std::span<const ScanImage> loose_images, const std::string& coordinate_metadata) {
  E57Writer writer(path, coordinate_metadata);
  for (const E57ScanOutput& output : scans) writer.add(output);
  writer.commit(loose_images);
}

}  // namespace scanbench::acquisition

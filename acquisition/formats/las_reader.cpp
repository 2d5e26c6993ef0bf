#include "acquisition/formats/las_reader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/formats/point_cloud.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"
#include "core/text.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::size_t kVlrHeaderSize = 54;
constexpr std::uint64_t kBlock = 1 << 16;  // records read at a time
// Record sizes of point data formats 0–10, and where their colour starts
// (0: none).
constexpr std::array<std::uint16_t, 11> kRecordSize = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
constexpr std::array<std::uint16_t, 11> kColourAt = {0, 0, 20, 28, 0, 28, 0, 30, 30, 0, 30};

class LasFile {
 public:
  explicit LasFile(const std::filesystem::path& path) : name_(path.string()) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) fail(0, "missing or not a regular file");
    size_ = std::filesystem::file_size(path, error);
    file_ = std::fopen(path.c_str(), "rb");
    if (file_ == nullptr) throw core::RuntimeFailure(name_, {}, "cannot open the file");
  }
  ~LasFile() {
    if (file_ != nullptr) std::fclose(file_);
  }
  LasFile(const LasFile&) = delete;
  LasFile& operator=(const LasFile&) = delete;

  std::uint64_t size() const { return size_; }

  // `bytes` bytes at `offset` into `out`, or an error naming `what` as cut short.
  void read_into(std::uint64_t offset, std::size_t bytes, const std::string& what,
                 std::vector<unsigned char>& out) {
    if (offset > size_ || size_ - offset < bytes) fail(offset, what + " is cut short");
    out.resize(bytes);
    if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0 ||
        std::fread(out.data(), 1, bytes, file_) != bytes) {
      throw core::RuntimeFailure(name_, {std::nullopt, offset, ""}, "cannot read " + what);
    }
  }
  std::vector<unsigned char> read(std::uint64_t offset, std::size_t bytes,
                                  const std::string& what) {
    std::vector<unsigned char> out;
    read_into(offset, bytes, what, out);
    return out;
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& problem) const {
    throw core::InputError(name_, {std::nullopt, offset, ""}, problem);
  }

 private:
  std::string name_;
  std::uint64_t size_ = 0;
  std::FILE* file_ = nullptr;
};

template <typename T>
T at(const std::vector<unsigned char>& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;  // LAS is little-endian, as every machine we build for
}

std::string text(const std::vector<unsigned char>& bytes, std::size_t offset, std::size_t size) {
  std::string out(reinterpret_cast<const char*>(bytes.data() + offset), size);
  return out.substr(0, out.find('\0'));
}

struct Header {
  int version_minor = 0;
  std::uint16_t header_size = 0;
  std::uint32_t point_offset = 0;
  std::uint32_t vlr_count = 0;
  int format = 0;
  std::uint16_t record_length = 0;
  std::uint64_t points = 0;
  Eigen::Vector3d scale, offset;
};

Header read_header(LasFile& file) {
  const std::vector<unsigned char> h = file.read(0, 227, "the header");
  if (text(h, 0, 4) != "LASF") file.fail(0, "not a LAS file (no \"LASF\" signature)");
  Header out;
  const int major = h[24];
  out.version_minor = h[25];
  if (major != 1 || out.version_minor > 4) {
    file.fail(24, "LAS version " + std::to_string(major) + "." + std::to_string(out.version_minor) +
                      " (1.0 to 1.4 are read)");
  }
  out.header_size = at<std::uint16_t>(h, 94);
  // The header's fixed part: 227 bytes up to 1.2, 235 in 1.3, 375 in 1.4.
  const std::uint16_t fixed = out.version_minor >= 4 ? 375 : out.version_minor == 3 ? 235 : 227;
  if (out.header_size < fixed) {
    file.fail(94, "a header size of " + std::to_string(out.header_size) +
                      " bytes, less than LAS 1." + std::to_string(out.version_minor) + "'s " +
                      std::to_string(fixed));
  }
  out.point_offset = at<std::uint32_t>(h, 96);
  if (out.point_offset < out.header_size) {
    file.fail(96, "points at byte " + std::to_string(out.point_offset) + ", inside the " +
                      std::to_string(out.header_size) + "-byte header");
  }
  out.vlr_count = at<std::uint32_t>(h, 100);
  const int format_byte = h[104];
  if (format_byte & 0xC0) {
    file.fail(104,
              "a LAZ (LASzip-compressed) file, which scanbench cannot read: Debian does not "
              "package LASzip; decompress it to LAS first (laszip -i FILE.laz -o FILE.las, "
              "or pdal translate)");
  }
  out.format = format_byte;
  if (out.format > 10) file.fail(104, "unknown point data format " + std::to_string(out.format));
  out.record_length = at<std::uint16_t>(h, 105);
  if (out.record_length < kRecordSize[static_cast<std::size_t>(out.format)]) {
    file.fail(105, "records of " + std::to_string(out.record_length) +
                       " bytes, shorter than point data format " + std::to_string(out.format) +
                       "'s " + std::to_string(kRecordSize[static_cast<std::size_t>(out.format)]));
  }
  out.points = at<std::uint32_t>(h, 107);
  if (out.version_minor >= 4) {
    const std::vector<unsigned char> wide = file.read(247, 8, "the LAS 1.4 header");
    if (at<std::uint64_t>(wide, 0) != 0) out.points = at<std::uint64_t>(wide, 0);
  }
  for (int axis = 0; axis < 3; ++axis) {
    out.scale[axis] = at<double>(h, 131 + 8 * static_cast<std::size_t>(axis));
    out.offset[axis] = at<double>(h, 155 + 8 * static_cast<std::size_t>(axis));
  }
  if (!(out.scale.allFinite() && out.scale.minCoeff() > 0.0 && out.offset.allFinite())) {
    file.fail(131, "scale factors or offsets that are not positive, finite numbers");
  }
  return out;
}

// "EPSG:N" from a GeoTIFF key directory: its projected, else its
// geographic coordinate system key; empty when it names none.
std::string epsg_from_geokeys(const std::vector<unsigned char>& keys) {
  if (keys.size() < 8) return {};
  const std::size_t count = at<std::uint16_t>(keys, 6);
  std::string geographic;
  for (std::size_t k = 0; k < count && 8 + 8 * k + 8 <= keys.size(); ++k) {
    const std::size_t e = 8 + 8 * k;
    const auto id = at<std::uint16_t>(keys, e), location = at<std::uint16_t>(keys, e + 2);
    const auto value = at<std::uint16_t>(keys, e + 6);
    if (location != 0 || value == 0 || value == 32767) continue;   // not a code, or user-defined
    if (id == 3072) return "EPSG:" + std::to_string(value);        // ProjectedCSTypeGeoKey
    if (id == 2048) geographic = "EPSG:" + std::to_string(value);  // GeographicTypeGeoKey
  }
  return geographic;
}

// One field of the extra bytes the Extra Bytes record describes, which
// the reader keeps: where it lies in a record and how to read it.
struct ExtraField {
  std::size_t at = 0;  // byte offset in the record
  int type = 0;        // 1–10: u8, i8, u16, i16, u32, i32, u64, i64, f32, f64
  double scale = 1.0, offset = 0.0;
  std::optional<double> no_data;
};

// Bytes of an extra bytes data type (LAS 1.4 table 24): 0 is `options`
// undocumented bytes, 1–10 scalars, 11–30 deprecated arrays of two and
// three; 0 for a type the table does not have.
std::size_t extra_type_size(int type, int options) {
  static constexpr std::array<std::size_t, 11> kScalar = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  if (type == 0) return static_cast<std::size_t>(options);
  if (type <= 10) return kScalar[static_cast<std::size_t>(type)];
  if (type <= 20) return 2 * kScalar[static_cast<std::size_t>(type - 10)];
  if (type <= 30) return 3 * kScalar[static_cast<std::size_t>(type - 20)];
  return 0;
}

double extra_value(const unsigned char* p, int type) {
  const auto load = [p](auto value) {
    std::memcpy(&value, p, sizeof value);
    return static_cast<double>(value);
  };
  switch (type) {
    case 1:
      return load(std::uint8_t{});
    case 2:
      return load(std::int8_t{});
    case 3:
      return load(std::uint16_t{});
    case 4:
      return load(std::int16_t{});
    case 5:
      return load(std::uint32_t{});
    case 6:
      return load(std::int32_t{});
    case 7:
      return load(std::uint64_t{});
    case 8:
      return load(std::int64_t{});
    case 9:
      return load(float{});
    default:
      return load(double{});
  }
}

// The recorded geometry among the extra bytes: normal x, y, z and
// footprint, by the names our export and other tools give them.
struct ExtraGeometry {
  std::array<std::optional<ExtraField>, 3> normal;
  std::optional<ExtraField> footprint;
};

// `name` without case, underscores and spaces: NormalX, normal_x, Normal X.
std::string squeezed_lower(const std::string& name) {
  std::string out = core::ascii_lower(name);
  std::erase_if(out, [](char c) { return c == '_' || c == ' '; });
  return out;
}

// Reads the Extra Bytes record (`data`, at file offset `offset`): the
// fields of the recorded geometry, laid out after the `base` bytes of the
// point format in records of `record_length` bytes.
ExtraGeometry extra_geometry(LasFile& file, std::uint64_t offset,
                             const std::vector<unsigned char>& data, std::size_t base,
                             std::size_t record_length) {
  constexpr std::size_t kDescriptor = 192;
  if (data.size() % kDescriptor != 0) {
    file.fail(offset, "an extra bytes record of " + std::to_string(data.size()) +
                          " bytes, not a whole number of 192-byte descriptors");
  }
  ExtraGeometry out;
  std::size_t next = base;
  for (std::size_t d = 0; d < data.size(); d += kDescriptor) {
    const int type = data[d + 2], options = data[d + 3];
    const std::string name = text(data, d + 4, 32);
    const std::size_t size = extra_type_size(type, options);
    if (size == 0) {
      file.fail(offset + d + 2, "extra bytes field \"" + name + "\" " +
                                    (type == 0 ? std::string("has no bytes")
                                               : "has unknown data type " + std::to_string(type)));
    }
    if (next + size > record_length) {
      file.fail(offset + d, "extra bytes field \"" + name + "\" ends at byte " +
                                std::to_string(next + size) + " of " +
                                std::to_string(record_length) + "-byte records");
    }
    ExtraField field;
    field.at = next;
    field.type = type;
    // no_data is an "anytype": a scalar widened to 64 bits (u64, i64, f64).
    const int wide_type = type >= 9 ? 10 : type % 2 == 1 ? 7 : 8;
    if ((options & 0x01) && type >= 1 && type <= 10)
      field.no_data = extra_value(data.data() + d + 40, wide_type);
    if (options & 0x08) field.scale = at<double>(data, d + 112);
    if (options & 0x10) field.offset = at<double>(data, d + 136);
    next += size;
    if (type < 1 || type > 10) continue;  // not a scalar: not geometry
    const std::string key = squeezed_lower(name);
    for (int axis = 0; axis < 3; ++axis) {
      const char letter = static_cast<char>('x' + axis);
      if (key == std::string("normal") + letter || key == std::string("n") + letter)
        out.normal[static_cast<std::size_t>(axis)] = field;
    }
    if (key == "footprint" || key == "radius") out.footprint = field;
  }
  const auto found = std::count_if(out.normal.begin(), out.normal.end(),
                                   [](const auto& f) { return f.has_value(); });
  if (found % 3 != 0) {
    file.fail(offset, "the extra bytes hold some but not all of NormalX, NormalY and NormalZ");
  }
  return out;
}

// What the variable length records say: the coordinate system (OGC WKT
// first, then GeoTIFF keys) and the recorded geometry in the extra bytes.
struct Records {
  std::string coordinate_system;
  ExtraGeometry extra;
};

Records read_records(LasFile& file, const Header& h) {
  std::string wkt, geotiff;
  Records out;
  std::uint64_t offset = h.header_size;
  for (std::uint32_t k = 0; k < h.vlr_count; ++k) {
    const std::string what = "variable length record " + std::to_string(k);
    const std::vector<unsigned char> vlr = file.read(offset, kVlrHeaderSize, what);
    const std::string user = text(vlr, 2, 16);
    const auto record = at<std::uint16_t>(vlr, 18);
    const auto length = at<std::uint16_t>(vlr, 20);
    const std::uint64_t data_at = offset + kVlrHeaderSize;
    if (user == "LASF_Projection" && (record == 2112 || record == 34735)) {
      const std::vector<unsigned char> data = file.read(data_at, length, what);
      if (record == 2112) wkt = text(data, 0, data.size());
      if (record == 34735) geotiff = epsg_from_geokeys(data);
    }
    if (user == "LASF_Spec" && record == 4) {
      out.extra = extra_geometry(file, data_at, file.read(data_at, length, what),
                                 kRecordSize[static_cast<std::size_t>(h.format)], h.record_length);
    }
    offset += kVlrHeaderSize + length;
  }
  out.coordinate_system = wkt.empty() ? geotiff : wkt;
  return out;
}

// The value of `field` in the record at `r`; NaN for its no-data value.
float extra_at(const std::vector<unsigned char>& block, std::size_t r, const ExtraField& field) {
  const double raw = extra_value(block.data() + r + field.at, field.type);
  const double value = raw * field.scale + field.offset;
  // No data, or beyond a float: no value (NaN, which the cloud reads as none).
  constexpr double kLargest = std::numeric_limits<float>::max();
  if ((field.no_data && raw == *field.no_data) || !(std::abs(value) <= kLargest))
    return std::numeric_limits<float>::quiet_NaN();
  return static_cast<float>(value);
}

}  // namespace

std::vector<ImportedScan> read_las(const std::filesystem::path& path) {
  LasFile file(path);
  const Header h = read_header(file);
  const std::uint64_t bytes = h.points * h.record_length;
  if (h.points > 0 && (bytes / h.points != h.record_length || h.point_offset > file.size() ||
                       file.size() - h.point_offset < bytes)) {
    file.fail(h.point_offset, "the header's " + std::to_string(h.points) +
                                  " records are cut short (the file holds " +
                                  std::to_string(file.size()) + " bytes)");
  }
  // Each point in double, 16-bit colour, and the scan's layers.
  core::check_memory(h.points * 64, path.string());
  const Records records = read_records(file, h);
  const ExtraGeometry& extra = records.extra;
  const std::size_t colour_at = kColourAt[static_cast<std::size_t>(h.format)];
  const std::size_t pixels = scattered_pixel_count(h.points);  // the scan pads to its last row
  PointCloud cloud;
  core::reserve_mapped(cloud.points, pixels);
  cloud.points.resize(h.points);
  std::vector<Eigen::Vector3d>& points = cloud.points;
  core::reserve_mapped(cloud.intensity, pixels);
  cloud.intensity.resize(h.points);
  if (extra.normal[0]) {
    core::reserve_mapped(cloud.normal, pixels);
    cloud.normal.resize(h.points);
  }
  if (extra.footprint) {
    core::reserve_mapped(cloud.footprint_m, pixels);
    cloud.footprint_m.resize(h.points);
  }
  std::vector<std::uint16_t> colour;
  if (colour_at > 0) core::assign_mapped(colour, 3 * h.points, std::uint16_t{0});
  std::vector<unsigned char> block;
  for (std::uint64_t first = 0; first < h.points; first += kBlock) {
    const std::uint64_t count = std::min(kBlock, h.points - first);
    file.read_into(h.point_offset + first * h.record_length, count * h.record_length,
                   "record " + std::to_string(first), block);
    for (std::uint64_t k = 0; k < count; ++k) {
      const std::size_t r = k * h.record_length;
      const std::size_t i = first + k;
      for (int axis = 0; axis < 3; ++axis) {
        points[i][axis] =
            at<std::int32_t>(block, r + 4 * static_cast<std::size_t>(axis)) * h.scale[axis] +
            h.offset[axis];
      }
      if (!(points[i].cwiseAbs().maxCoeff() <= kMaxCoordinateM)) {
        file.fail(h.point_offset + i * h.record_length,
                  "record " + std::to_string(i) +
                      ": coordinate beyond 10^8 m (a corrupt value, scale or offset?)");
      }
      cloud.intensity[i] = static_cast<float>(at<std::uint16_t>(block, r + 12) / 65535.0);
      for (std::size_t c = 0; c < (colour_at > 0 ? 3u : 0u); ++c) {
        colour[3 * i + c] = at<std::uint16_t>(block, r + colour_at + 2 * c);
      }
      if (extra.normal[0]) {
        for (int axis = 0; axis < 3; ++axis)
          cloud.normal[i][axis] = extra_at(block, r, *extra.normal[static_cast<std::size_t>(axis)]);
      }
      if (extra.footprint) cloud.footprint_m[i] = extra_at(block, r, *extra.footprint);
    }
  }
  const bool wide_colour =
      std::any_of(colour.begin(), colour.end(), [](std::uint16_t v) { return v > 255; });
  if (!colour.empty()) core::reserve_mapped(cloud.rgb, 3 * pixels);
  cloud.rgb.resize(colour.size());
  for (std::size_t k = 0; k < colour.size(); ++k) {
    cloud.rgb[k] = static_cast<std::uint8_t>(wide_colour ? (colour[k] + 128) / 257 : colour[k]);
  }
  std::vector<ImportedScan> out = scattered_scans(std::move(cloud), path);
  for (ImportedScan& scan : out) {
    scan.source.format = "las";
    if (out.size() == 1) scan.source.points_in_file = h.points;
    scan.source.coordinate_metadata = records.coordinate_system;
  }
  return out;
}

}  // namespace scanbench::acquisition

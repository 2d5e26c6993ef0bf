// Our own PCD reader: the header is checked whole before anything is
// allocated (pcd_header.hpp), every allocation is bounded by the file's
// size, the ASCII body is checked value by value, and compressed bodies are
// decoded with bounds on every run (lzf.hpp).
#include "acquisition/formats/pcd_reader.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <string_view>
#include <utility>
#include <vector>

#include "acquisition/formats/lzf.hpp"
#include "acquisition/formats/pcd_header.hpp"
#include "acquisition/formats/point_cloud.hpp"
#include "acquisition/formats/text_lines.hpp"
#include "acquisition/local_origin.hpp"
#include "core/memory.hpp"

namespace scanbench::acquisition {
namespace {

static_assert(std::endian::native == std::endian::little, "PCD binary bodies are little-endian");

// LZF makes at most ~132 bytes of one; beyond 256 the header lies.
constexpr std::uint64_t kMaxCompressionRatio = 256;

// The fields a Scan is made of, looked up once rather than per point.
struct Fields {
  const PcdField *x, *y, *z, *rgb, *intensity;  // rgb: "rgb" or "rgba"; null: absent
};

Fields check_fields(TextLineReader& reader, const PcdHeader& header) {
  for (const char* name : {"x", "y", "z"}) {
    const PcdField* field = find_field(header, name);
    if (field == nullptr) reader.fail(std::string("missing field ") + name);
    if (field->type != 'F' || field->count != 1) {
      reader.fail("field " + field->name + " must be one float");
    }
  }
  Fields f{find_field(header, "x"), find_field(header, "y"), find_field(header, "z"),
           find_field(header, "rgb"), find_field(header, "intensity")};
  if (f.rgb == nullptr) f.rgb = find_field(header, "rgba");
  if (f.rgb != nullptr && (f.rgb->size != 4 || f.rgb->count != 1)) {
    reader.fail("field " + f.rgb->name + " must be one packed 4-byte value");
  }
  if (f.intensity != nullptr && f.intensity->count != 1) {
    reader.fail("field intensity must be one value");
  }
  return f;
}

// Calls visit(T{}) with T the C++ type of `field`'s values (TYPE and SIZE).
template <typename Visit>
auto with_value_type(const PcdField& field, Visit&& visit) {
  switch (field.type) {
    case 'F':
      return field.size == 4 ? visit(float{}) : visit(double{});
    case 'I':
      return field.size == 1   ? visit(std::int8_t{})
             : field.size == 2 ? visit(std::int16_t{})
             : field.size == 4 ? visit(std::int32_t{})
                               : visit(std::int64_t{});
    default:
      return field.size == 1   ? visit(std::uint8_t{})
             : field.size == 2 ? visit(std::uint16_t{})
             : field.size == 4 ? visit(std::uint32_t{})
                               : visit(std::uint64_t{});
  }
}

// The first value of `field` from its little-endian bytes at `p`.
double value_at(const std::uint8_t* p, const PcdField& field) {
  return with_value_type(field, [p]<typename T>(T) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return static_cast<double>(value);
  });
}

// A whole ASCII token as the field's type, stored as its little-endian
// bytes in `out` (8 bytes), as a binary body would hold it. Floats accept
// nan and inf (PCL writes "nan"); a leading '+' is tolerated because
// hand-written files use it. False when the token is not such a number.
bool parse_token(std::string_view token, const PcdField& field, std::uint8_t* out) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* first = token.data();
  const char* last = first + token.size();
  return with_value_type(field, [&]<typename T>(T value) {
    const auto [end, error] = std::from_chars(first, last, value);
    if (error != std::errc() || end != last) return false;
    std::memcpy(out, &value, sizeof(T));
    return true;
  });
}

// The body as binary points (point_step bytes each, fields at their
// offsets): ASCII values are converted to the bytes a binary body holds.
std::vector<std::uint8_t> read_ascii_body(TextLineReader& reader, const PcdHeader& h) {
  // At least a digit and a separator per value.
  if (reader.file_size() - h.body_offset < h.points * 2 * h.values_per_point) {
    reader.fail("truncated ASCII body");
  }
  std::vector<std::uint8_t> body(h.points * h.point_step);
  std::vector<std::string_view> tokens;
  std::string_view line;
  std::uint64_t points = 0;
  while (reader.next(line)) {
    tokens.clear();
    for (std::size_t start = 0; (start = line.find_first_not_of(" \t\r", start)) != line.npos;) {
      const std::size_t end = std::min(line.find_first_of(" \t\r", start), line.size());
      tokens.push_back(line.substr(start, end - start));
      start = end;
    }
    if (tokens.empty()) continue;
    if (points == h.points) reader.fail("more points in the ASCII body than POINTS says");
    if (tokens.size() != h.values_per_point) {
      reader.fail(std::to_string(tokens.size()) + " values, the header says " +
                  std::to_string(h.values_per_point));
    }
    std::uint8_t* point = body.data() + points * h.point_step;
    for (const PcdField& field : h.fields) {
      for (std::uint64_t k = 0; k < field.count; ++k) {
        std::uint8_t bytes[8] = {};
        const std::string_view token = tokens[field.column + k];
        if (!parse_token(token, field, bytes)) {
          const std::string shown(token.substr(0, 40));
          reader.fail("value '" + shown + "' is not a number of the field's type (" + field.name +
                      ": " + field.type + std::to_string(field.size) + ")");
        }
        std::memcpy(point + field.offset + k * field.size, bytes, field.size);
      }
    }
    ++points;
  }
  if (points < h.points) {
    reader.fail("truncated ASCII body: " + std::to_string(points) + " of " +
                std::to_string(h.points) + " points");
  }
  return body;
}

// Where the body is read from: the reader for messages, the path for bytes.
struct Body {
  const TextLineReader& reader;
  const std::filesystem::path& path;
};

std::vector<std::uint8_t> read_bytes(const Body& source, std::uint64_t offset,
                                     std::uint64_t count) {
  const TextLineReader& reader = source.reader;
  std::vector<std::uint8_t> bytes(count);
  std::ifstream in(source.path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(offset));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(count));
  if (static_cast<std::uint64_t>(in.gcount()) != count) reader.fail("cannot read the body");
  return bytes;
}

std::vector<std::uint8_t> read_binary_body(const Body& source, const PcdHeader& h) {
  const TextLineReader& reader = source.reader;
  const std::uint64_t available = reader.file_size() - h.body_offset;
  const std::uint64_t needed = h.points * h.point_step;
  if (available < needed) {
    reader.fail("truncated binary body (" + std::to_string(available) + " of " +
                std::to_string(needed) + " bytes)");
  }
  return read_bytes(source, h.body_offset, needed);
}

// PCL's compressed body: two uint32 (compressed, uncompressed size), then
// LZF data that decodes to the fields one after another, each for all
// points (field-major). Returned point-major like a binary body.
std::vector<std::uint8_t> read_compressed_body(const Body& source, const PcdHeader& h) {
  const TextLineReader& reader = source.reader;
  const std::uint64_t available = reader.file_size() - h.body_offset;
  const std::uint64_t needed = h.points * h.point_step;
  if (available < 8) reader.fail("truncated compressed body");
  const std::vector<std::uint8_t> sizes = read_bytes(source, h.body_offset, 8);
  std::uint32_t compressed = 0, uncompressed = 0;
  std::memcpy(&compressed, sizes.data(), 4);
  std::memcpy(&uncompressed, sizes.data() + 4, 4);
  if (available < 8 + std::uint64_t{compressed}) reader.fail("truncated compressed body");
  if (uncompressed != needed || needed > kMaxCompressionRatio * compressed + 64) {
    reader.fail("compressed body size disagrees with the header (" + std::to_string(uncompressed) +
                " bytes, not " + std::to_string(needed) + ")");
  }
  const std::vector<std::uint8_t> packed = read_bytes(source, h.body_offset + 8, compressed);
  std::vector<std::uint8_t> by_field(needed);
  if (const auto problem = lzf_decompress(packed, by_field)) {
    reader.fail("damaged compressed body: " + *problem);
  }
  std::vector<std::uint8_t> body(needed);
  std::uint64_t field_start = 0;
  for (const PcdField& field : h.fields) {
    const std::uint64_t bytes = field.size * field.count;
    for (std::uint64_t i = 0; i < h.points; ++i) {
      std::memcpy(body.data() + i * h.point_step + field.offset,
                  by_field.data() + field_start + i * bytes, bytes);
    }
    field_start += bytes * h.points;
  }
  return body;
}

// Coordinates beyond this [m] are no place on or near the Earth: a corrupt
// value, refused before it makes a range that no float holds.

// Refuses a point whose values do not fit what the scan stores.
void check_fits(TextLineReader& reader, const Eigen::Vector3d& p, double intensity, std::size_t i,
                const PcdHeader& h) {
  const auto where = [&] {
    return "point " + std::to_string(i) + " (row " + std::to_string(i / h.width) + ", col " +
           std::to_string(i % h.width) + "): ";
  };
  if (p.allFinite() && p.cwiseAbs().maxCoeff() > kMaxCoordinateM) {
    reader.fail(where() + "coordinate beyond 10^8 m (a corrupt value?)");
  }
  if (std::abs(intensity) > std::numeric_limits<float>::max()) {
    reader.fail(where() + "intensity does not fit a float");
  }
}

// x, y, z of one point: the common 4-byte floats read directly.
Eigen::Vector3d coordinates(const std::uint8_t* point, const Fields& f, bool floats) {
  if (floats) {
    float v[3];
    std::memcpy(&v[0], point + f.x->offset, 4);
    std::memcpy(&v[1], point + f.y->offset, 4);
    std::memcpy(&v[2], point + f.z->offset, 4);
    return Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return {value_at(point + f.x->offset, *f.x), value_at(point + f.y->offset, *f.y),
          value_at(point + f.z->offset, *f.z)};
}

// An unorganized cloud (HEIGHT 1) read as one row: its points with a
// return, in the file's order, as a scattered scan (scan.hpp), or tiles of
// a cloud too wide for one (point_cloud.hpp), in the row's pose.
std::vector<ImportedScan> scattered(const Scan& row, const std::vector<Eigen::Vector3d>& points,
                                    const std::filesystem::path& path) {
  PointCloud cloud;
  const std::size_t returns = count_valid(row);
  cloud.points.reserve(scattered_pixel_count(returns));
  if (row.has_intensity()) cloud.intensity.reserve(scattered_pixel_count(returns));
  if (row.has_color()) cloud.rgb.reserve(3 * scattered_pixel_count(returns));
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!row.valid[i]) continue;
    cloud.points.push_back(points[i]);
    if (row.has_intensity()) cloud.intensity.push_back(row.intensity[i]);
    if (row.has_color()) cloud.rgb.insert(cloud.rgb.end(), &row.rgb[3 * i], &row.rgb[3 * i + 3]);
  }
  std::vector<ImportedScan> out = scattered_scans(std::move(cloud), path);
  for (ImportedScan& part : out) part.scan.T_world_scan = row.T_world_scan * part.scan.T_world_scan;
  return out;
}

std::vector<ImportedScan> to_scans(TextLineReader& reader, const std::filesystem::path& path,
                                   const std::vector<std::uint8_t>& body, const PcdHeader& h,
                                   const Fields& f) {
  Scan scan = make_empty_scan(static_cast<int>(h.height), static_cast<int>(h.width),
                              f.intensity != nullptr, f.rgb != nullptr);
  const std::size_t n = scan.pixel_count();
  const bool floats = f.x->size == 4 && f.y->size == 4 && f.z->size == 4;
  std::vector<Eigen::Vector3d> points(n, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = body.data() + i * h.point_step;
    const Eigen::Vector3d p = coordinates(point, f, floats);
    const double intensity =
        f.intensity != nullptr ? value_at(point + f.intensity->offset, *f.intensity) : 0.0;
    check_fits(reader, p, intensity, i, h);
    if (p.allFinite() && !p.isZero(0.0)) {
      points[i] = p;
      scan.valid[i] = 1;
    }
    if (f.intensity != nullptr) scan.intensity[i] = static_cast<float>(intensity);
    if (f.rgb != nullptr) {
      std::uint32_t packed = 0;  // the bits of the field, whatever its declared type
      std::memcpy(&packed, point + f.rgb->offset, 4);
      scan.rgb[3 * i + 0] = static_cast<std::uint8_t>(packed >> 16);
      scan.rgb[3 * i + 1] = static_cast<std::uint8_t>(packed >> 8);
      scan.rgb[3 * i + 2] = static_cast<std::uint8_t>(packed);
    }
  }
  scan.T_world_scan = h.viewpoint;
  if (h.height == 1) {
    if (count_valid(scan) == 0) reader.fail("no point with a return: there is nothing to import");
    return scattered(scan, points, path);
  }
  LocalOriginSettings grid;
  grid.try_spherical = false;  // depth-camera grids are pinhole images, not panoramas
  set_grid_from_points(scan, points, std::nullopt, grid);
  std::vector<ImportedScan> out(1);
  out[0].scan = std::move(scan);
  return out;
}

}  // namespace

std::vector<ImportedScan> read_pcd(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    const std::u8string utf8 = path.u8string();
    throw core::InputError(std::string(utf8.begin(), utf8.end()), {},
                           "missing or not a regular file");
  }
  TextLineReader reader(path);
  if (reader.file_size() == 0) reader.fail("empty file");
  const PcdHeader header = read_pcd_header(reader);
  const Fields fields = check_fields(reader, header);
  // The body (twice while a compressed one is decoded), then the scan and
  // the points in double: about 48 bytes per pixel beside the body.
  const std::uint64_t body_bytes = header.points * header.point_step;
  core::check_memory(
      (header.data == PcdData::kBinaryCompressed ? 2 : 1) * body_bytes + 48 * header.points,
      reader.file_name());
  std::vector<std::uint8_t> body;
  switch (header.data) {
    case PcdData::kAscii:
      body = read_ascii_body(reader, header);
      break;
    case PcdData::kBinary:
      body = read_binary_body({reader, path}, header);
      break;
    case PcdData::kBinaryCompressed:
      body = read_compressed_body({reader, path}, header);
      break;
  }
  std::vector<ImportedScan> out = to_scans(reader, path, body, header, fields);
  const std::u8string stem = path.stem().u8string();
  const std::u8string utf8 = path.u8string();
  name_tiles(out, std::string(stem.begin(), stem.end()));
  for (ImportedScan& part : out) {
    part.scan.scanner = ScannerMetadata{.name = "",
                                        .source_file = std::string(utf8.begin(), utf8.end()),
                                        .position_world = header.viewpoint.translation()};
    part.source.format = "pcd";
    if (out.size() == 1) part.source.points_in_file = header.points;  // returns or not
  }
  return out;
}

}  // namespace scanbench::acquisition

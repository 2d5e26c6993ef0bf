// PCL 1.13's reader trusts its input: readHeader allocates POINTS × point_step
// before any check, VIEWPOINT is parsed with unchecked stream reads (a bad token
// leaves floats uninitialised), non-numeric ASCII values become 0, ASCII lines
// with too few values are skipped, compressed size words are believed. So our
// own header scan first bounds every allocation by the file size, the ASCII
// body is checked token by token, and only then does PCL read the file.
#include "acquisition/pcd_reader.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "acquisition/rigid_transform.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kMaxSide = 1'000'000;
constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 31;
constexpr std::size_t kMaxHeaderLines = 1000;
constexpr std::uint64_t kMaxCount = 4096;  // values per field (PCL's largest descriptors: ~1000)
// LZF makes at most ~132 bytes of one; beyond 256 the header lies.
constexpr std::uint64_t kMaxCompressionRatio = 256;

struct Source {
  std::filesystem::path path;
  std::string file;  // UTF-8, for messages
  std::uint64_t size = 0;

  [[noreturn]] void fail(const std::string& problem, std::optional<std::uint64_t> line = {}) const {
    core::FilePosition position;
    position.line = line;
    throw core::InputError(file, position, problem);
  }
};

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t start = 0;
  while ((start = line.find_first_not_of(" \t\r", start)) != std::string_view::npos) {
    const std::size_t end = std::min(line.find_first_of(" \t\r", start), line.size());
    tokens.push_back(line.substr(start, end - start));
    start = end;
  }
  return tokens;
}

// Whole-token numbers only: "1.5x" is not 1.5. Floats accept nan and inf (PCL
// writes "nan"); a leading '+' is tolerated because hand-written files use it.
template <typename T>
std::optional<T> parse(std::string_view token) {
  if (std::is_floating_point_v<T> && !token.empty() && token.front() == '+') token.remove_prefix(1);
  T value{};
  const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (error != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

// What our own header scan learns; PCL stays the authority on fields and types.
struct HeaderScan {
  std::optional<std::uint64_t> width, height, points;
  std::vector<std::uint64_t> sizes, counts;
  std::string data;                    // ascii, binary or binary_compressed
  std::uint64_t body_offset = 0;       // first byte after the DATA line
  std::uint64_t body_line = 0;         // 1-based line number of the first body line
  std::uint64_t point_step = 0;        // bytes per point: Σ SIZE · COUNT
  std::uint64_t values_per_point = 0;  // ASCII tokens per point: Σ COUNT
};

// SIZE values are 1, 2, 4 or 8 bytes and COUNT values at most kMaxCount, so
// that no product of header numbers can overflow.
std::vector<std::uint64_t> counts_of(const Source& src, const std::vector<std::string_view>& tokens,
                                     std::uint64_t line) {
  std::vector<std::uint64_t> values;
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    const auto v = parse<std::uint64_t>(tokens[i]);
    const bool ok = v && (tokens[0] == "SIZE" ? (*v == 1 || *v == 2 || *v == 4 || *v == 8)
                                              : (*v >= 1 && *v <= kMaxCount));
    if (!ok)
      src.fail(std::string(tokens[0]) + " value " + std::string(tokens[i]) + " is absurd", line);
    values.push_back(*v);
  }
  return values;
}

void check_viewpoint_tokens(const Source& src, const std::vector<std::string_view>& tokens,
                            std::uint64_t line) {
  if (tokens.size() != 8) src.fail("VIEWPOINT needs 7 numbers (tx ty tz qw qx qy qz)", line);
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    const auto value = parse<double>(tokens[i]);
    if (!value) src.fail("VIEWPOINT value '" + std::string(tokens[i]) + "' is not a number", line);
    if (!std::isfinite(*value) || std::abs(*value) > std::numeric_limits<float>::max()) {
      src.fail("VIEWPOINT has a non-finite value", line);
    }
  }
}

// Returns true at the DATA line, which ends the header.
bool scan_header_line(const Source& src, const std::vector<std::string_view>& tokens,
                      std::uint64_t line, HeaderScan& h) {
  const std::string_view key = tokens[0];
  auto single = [&](std::optional<std::uint64_t>& out) {
    const auto value = tokens.size() == 2 ? parse<std::uint64_t>(tokens[1]) : std::nullopt;
    if (!value) src.fail(std::string(key) + " is not a non-negative integer", line);
    out = value;
  };
  if (key == "FIELDS" || key == "COLUMNS") {
    h.sizes.assign(tokens.size() - 1, 4);  // PCL's defaults for old files
    h.counts.assign(tokens.size() - 1, 1);
  } else if (key == "SIZE") {
    h.sizes = counts_of(src, tokens, line);
  } else if (key == "COUNT") {
    h.counts = counts_of(src, tokens, line);
  } else if (key == "WIDTH") {
    single(h.width);
  } else if (key == "HEIGHT") {
    single(h.height);
  } else if (key == "POINTS") {
    single(h.points);
  } else if (key == "VIEWPOINT") {
    check_viewpoint_tokens(src, tokens, line);
  } else if (key == "DATA") {
    if (tokens.size() != 2) src.fail("DATA line needs exactly one type", line);
    h.data = tokens[1];
    return true;
  } else if (key != "VERSION" && key != "TYPE") {
    src.fail("unexpected line in PCD header (not a PCD file?)", line);
  }
  return false;
}

HeaderScan scan_header(const Source& src) {
  std::ifstream in(src.path, std::ios::binary);
  if (!in) src.fail("cannot open file");
  HeaderScan h;
  std::string text;
  std::uint64_t line = 0;
  while (line < kMaxHeaderLines && std::getline(in, text)) {
    ++line;
    h.body_offset += text.size() + 1;
    const std::vector<std::string_view> tokens = split(text);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    if (scan_header_line(src, tokens, line, h)) {
      h.body_line = line + 1;
      return h;
    }
  }
  src.fail("no DATA line in the header (not a PCD file?)", line);
}

void check_dimensions(const Source& src, HeaderScan& h) {
  if (!h.points) src.fail("header has no POINTS line");
  if (h.sizes.empty()) src.fail("header has no FIELDS");
  if (h.sizes.size() != h.counts.size() || h.sizes.size() > kMaxHeaderLines) {
    src.fail("SIZE or COUNT disagrees with FIELDS in length");
  }
  for (std::size_t i = 0; i < h.sizes.size(); ++i) {
    h.point_step += h.sizes[i] * h.counts[i];
    h.values_per_point += h.counts[i];
  }
  const std::uint64_t height = h.height.value_or(1);
  const std::uint64_t width = h.width.value_or(*h.points);
  if (height <= 1) {
    src.fail("not an organized point cloud (height " + std::to_string(height) + ")");
  }
  if (width == 0 || *h.points == 0) src.fail("empty point cloud (no points)");
  if (width > kMaxSide || height > kMaxSide || *h.points > kMaxPoints) {
    src.fail("absurd dimensions (more than 1000000 a side or 2^31 points)");
  }
  if (width * height != *h.points) {
    src.fail("WIDTH x HEIGHT (" + std::to_string(width) + " x " + std::to_string(height) +
             ") disagrees with POINTS (" + std::to_string(*h.points) + ")");
  }
}

// Refuses a body that cannot hold what the header promises, before PCL maps or
// allocates anything for it.
void check_body_size(const Source& src, const HeaderScan& h) {
  const std::uint64_t available = src.size > h.body_offset ? src.size - h.body_offset : 0;
  const std::uint64_t needed = *h.points * h.point_step;
  if (h.data == "binary") {
    const std::string sizes = std::to_string(available) + " of " + std::to_string(needed);
    if (available < needed) src.fail("truncated binary body (" + sizes + " bytes)");
  } else if (h.data == "binary_compressed") {
    std::ifstream in(src.path, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(h.body_offset));
    std::uint32_t words[2] = {};  // compressed, uncompressed size; native order, as PCL writes
    in.read(reinterpret_cast<char*>(words), sizeof(words));
    if (!in || available < 8 + std::uint64_t{words[0]}) src.fail("truncated compressed body");
    if (words[1] != needed || needed > kMaxCompressionRatio * words[0] + 64) {
      src.fail("compressed body size disagrees with the header (" + std::to_string(words[1]) +
               " bytes, not " + std::to_string(needed) + ")");
    }
  } else if (h.data == "ascii") {
    // At least a digit and a separator per value.
    if (available < *h.points * 2 * h.values_per_point) src.fail("truncated ASCII body");
  } else {
    src.fail("unknown DATA type '" + h.data + "'");
  }
}

void check_ascii_body(const Source& src, const HeaderScan& h) {
  std::ifstream in(src.path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(h.body_offset));
  std::string text;
  std::uint64_t line = h.body_line - 1;
  std::uint64_t points = 0;
  while (std::getline(in, text)) {
    ++line;
    const std::vector<std::string_view> tokens = split(text);
    if (tokens.empty()) continue;
    if (points == *h.points) src.fail("more points in the ASCII body than POINTS says", line);
    const std::string count = std::to_string(tokens.size()) + " values";
    if (tokens.size() != h.values_per_point) {
      src.fail(count + ", the header says " + std::to_string(h.values_per_point), line);
    }
    for (const std::string_view t : tokens) {
      if (!parse<double>(t)) src.fail("value '" + std::string(t) + "' is not a number", line);
    }
    ++points;
  }
  const std::string read = std::to_string(points) + " of " + std::to_string(*h.points);
  if (points < *h.points) src.fail("truncated ASCII body: " + read + " points", line);
}

const pcl::PCLPointField* find_field(const pcl::PCLPointCloud2& cloud, std::string_view name) {
  for (const pcl::PCLPointField& field : cloud.fields) {
    if (field.name == name) return &field;
  }
  return nullptr;
}

// The fields a Scan is made of, looked up once rather than per point.
struct Fields {
  const pcl::PCLPointField *x, *y, *z, *rgb, *intensity;  // rgb: "rgb" or "rgba"; null: absent
};

Fields check_fields(const Source& src, const pcl::PCLPointCloud2& cloud) {
  for (const char* name : {"x", "y", "z"}) {
    const pcl::PCLPointField* field = find_field(cloud, name);
    if (field == nullptr) src.fail(std::string("missing field ") + name);
    const bool is_float = field->datatype == pcl::PCLPointField::FLOAT32 ||
                          field->datatype == pcl::PCLPointField::FLOAT64;
    if (!is_float || field->count != 1) src.fail("field " + field->name + " must be one float");
  }
  Fields f{find_field(cloud, "x"), find_field(cloud, "y"), find_field(cloud, "z"),
           find_field(cloud, "rgb"), find_field(cloud, "intensity")};
  if (f.rgb == nullptr) f.rgb = find_field(cloud, "rgba");
  if (f.rgb != nullptr && (pcl::getFieldSize(f.rgb->datatype) != 4 || f.rgb->count != 1)) {
    src.fail("field " + f.rgb->name + " must be one packed 4-byte value");
  }
  if (f.intensity != nullptr && f.intensity->count != 1) {
    src.fail("field intensity must be one value");
  }
  return f;
}

template <typename T>
double load(const std::uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return static_cast<double>(value);
}

// Indexed by PCLPointField::datatype (INT8 = 1 … FLOAT64 = 8, INT64, UINT64, BOOL).
using Loader = double (*)(const std::uint8_t*);
// clang-format off
constexpr Loader kLoaders[] = {nullptr, load<std::int8_t>, load<std::uint8_t>, load<std::int16_t>,
    load<std::uint16_t>, load<std::int32_t>, load<std::uint32_t>, load<float>, load<double>,
    load<std::int64_t>, load<std::uint64_t>, load<std::uint8_t>};
// clang-format on
static_assert(pcl::PCLPointField::FLOAT64 == 8 && pcl::PCLPointField::BOOL == 11);

double value_at(const std::uint8_t* point, const pcl::PCLPointField& field) {
  if (field.datatype == 0 || field.datatype >= std::size(kLoaders)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return kLoaders[field.datatype](point + field.offset);
}

Eigen::Isometry3d viewpoint_pose(const Source& src, const Eigen::Vector4f& origin,
                                 const Eigen::Quaternionf& orientation) {
  const Eigen::Quaterniond q = orientation.cast<double>();
  if (!origin.allFinite() || !q.coeffs().allFinite()) src.fail("VIEWPOINT is not finite");
  if (std::abs(q.norm() - 1.0) > kRigidTolerance) {
    src.fail("VIEWPOINT quaternion is not unit (norm " + std::to_string(q.norm()) + ")");
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  m.topRightCorner<3, 1>() = origin.head<3>().cast<double>();
  if (const std::string problem = rigid_transform_problem(m); !problem.empty()) {
    src.fail("VIEWPOINT: " + problem);
  }
  return to_isometry(m);
}

void fill_pixel(const Fields& f, const std::uint8_t* point, std::size_t i, Scan& scan,
                std::vector<Eigen::Vector3f>& directions) {
  const Eigen::Vector3d p(value_at(point, *f.x), value_at(point, *f.y), value_at(point, *f.z));
  if (p.allFinite() && !p.isZero(0.0)) {
    const double range = p.norm();
    scan.range_m[i] = static_cast<float>(range);
    scan.valid[i] = 1;
    directions[i] = (p / range).cast<float>();
  }
  if (f.intensity != nullptr) scan.intensity[i] = static_cast<float>(value_at(point, *f.intensity));
  if (f.rgb != nullptr) {
    std::uint32_t packed = 0;  // the bits of the field, whatever its declared type
    std::memcpy(&packed, point + f.rgb->offset, 4);
    scan.rgb[3 * i + 0] = static_cast<std::uint8_t>(packed >> 16);
    scan.rgb[3 * i + 1] = static_cast<std::uint8_t>(packed >> 8);
    scan.rgb[3 * i + 2] = static_cast<std::uint8_t>(packed);
  }
}

Scan to_scan(const Source& src, const pcl::PCLPointCloud2& cloud) {
  // PCL's read() rebuilt the field list; look the fields up again in it.
  const Fields f = check_fields(src, cloud);
  Scan scan = make_empty_scan(static_cast<int>(cloud.height), static_cast<int>(cloud.width),
                              f.intensity != nullptr, f.rgb != nullptr);
  const std::size_t n = scan.pixel_count();
  if (cloud.data.size() < n * cloud.point_step) src.fail("PCL returned fewer points than declared");
  std::vector<Eigen::Vector3f> directions(n, Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    fill_pixel(f, &cloud.data[i * cloud.point_step], i, scan, directions);
  }
  scan.angles = PerPixelDirections{std::move(directions)};
  return scan;
}

pcl::PCLPointCloud2 load_with_pcl(const Source& src, const HeaderScan& header,
                                  Eigen::Isometry3d& T_world_scan) {
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 cloud;
  Eigen::Vector4f origin = Eigen::Vector4f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  try {
    const std::string file = src.path.string();
    if (reader.readHeader(file, cloud, origin, orientation, version, data_type, data_index) < 0) {
      src.fail("PCL refused the header");
    }
    check_fields(src, cloud);
    T_world_scan = viewpoint_pose(src, origin, orientation);
    if (header.data == "ascii") check_ascii_body(src, header);
    if (reader.read(file, cloud, origin, orientation, version) < 0)
      src.fail("PCL could not read the body");
  } catch (const pcl::PCLException& e) {
    src.fail(std::string("PCL failed: ") + e.what());
  }
  return cloud;
}

Source open_source(const std::filesystem::path& path) {
  const std::u8string utf8 = path.u8string();
  Source src{.path = path, .file = std::string(utf8.begin(), utf8.end()), .size = 0};
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) src.fail("missing or not a regular file");
  src.size = std::filesystem::file_size(path, error);
  if (error || src.size == 0) src.fail(error ? "cannot determine the file size" : "empty file");
  return src;
}

}  // namespace

Scan read_organized_pcd(const std::filesystem::path& path) {
  // Errors reach the caller as InputError; PCL's own console messages would
  // only repeat them, out of order, on stderr. PCL's verbosity is
  // process-wide, so it is set once, not raced on by concurrent readers.
  static std::once_flag quiet;
  std::call_once(quiet, [] { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); });
  const Source src = open_source(path);
  HeaderScan header = scan_header(src);
  check_dimensions(src, header);
  check_body_size(src, header);
  Eigen::Isometry3d T_world_scan;
  const pcl::PCLPointCloud2 cloud = load_with_pcl(src, header, T_world_scan);
  Scan scan = to_scan(src, cloud);
  const std::u8string stem = path.stem().u8string();
  scan.name = std::string(stem.begin(), stem.end());
  scan.T_world_scan = T_world_scan;
  scan.scanner = ScannerMetadata{
      .name = "", .source_file = src.file, .position_world = T_world_scan.translation()};
  return scan;
}

}  // namespace scanbench::acquisition

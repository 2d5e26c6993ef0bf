#include "acquisition/formats/point_export.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cctype>
#include <cmath>
#include <cstring>
#include <ctime>
#include <limits>
#include <string_view>

#include "acquisition/formats/number_format.hpp"
#include "acquisition/formats/output_file.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

static_assert(std::endian::native == std::endian::little, "PLY export writes native little-endian");

using Channels = PointChannels;

Channels common_channels(std::span<const Scan> scans,
                         std::span<const ScanGeometry* const> geometry) {
  assert((geometry.empty() || geometry.size() == scans.size()) && "one geometry entry per scan");
  Channels channels;
  channels.geometry = !geometry.empty();
  for (std::size_t s = 0; s < scans.size(); ++s) {
    channels.intensity = channels.intensity && scans[s].has_intensity();
    channels.color = channels.color && scans[s].has_color();
    channels.geometry = channels.geometry && geometry[s] != nullptr;
  }
  return channels;
}

// Calls visit(pixel index, world point) for every exported pixel of one
// scan (valid, not a mixed pixel when geometry is exported, and kept when a
// keep mask is given), row-major; `scan` holds the grid's rows from
// `first_row` (direction_precise).
template <typename Visit>
void for_each_scan_point(const Scan& scan, const ScanGeometry* geometry,
                         const std::vector<std::uint8_t>* keep, bool with_geometry, int first_row,
                         Visit&& visit) {
  assert((keep == nullptr || keep->size() == scan.pixel_count()) && "a byte per pixel");
  assert((!with_geometry || geometry != nullptr) && "geometry to leave mixed pixels out");
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (with_geometry ? !in_model(scan, *geometry, i) : !scan.valid[i]) continue;
      if (keep != nullptr && (*keep)[i] == 0) continue;
      visit(i, point_in_world(scan, row, col, first_row));
    }
  }
}

// for_each_scan_point over every scan, with visit(scan index, pixel index,
// world point).
template <typename Visit>
void for_each_point(std::span<const Scan> scans, std::span<const ScanGeometry* const> geometry,
                    std::span<const std::vector<std::uint8_t>* const> keep, Channels channels,
                    Visit&& visit) {
  assert((keep.empty() || keep.size() == scans.size()) && "one keep entry per scan");
  for (std::size_t s = 0; s < scans.size(); ++s) {
    for_each_scan_point(scans[s], channels.geometry ? geometry[s] : nullptr,
                        keep.empty() ? nullptr : keep[s], channels.geometry, 0,
                        [&](std::size_t i, const Eigen::Vector3d& p) { visit(s, i, p); });
  }
}

template <typename T>
void append_binary(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// A point's normal (world frame) and footprint as four floats: what PLY and
// LAS both carry after the geometry stage.
void append_geometry(std::string& out, const Scan& scan, const ScanGeometry& geometry,
                     std::size_t i) {
  const Eigen::Vector3f n = scan.T_world_scan.linear().cast<float>() * geometry.normal[i];
  for (int axis = 0; axis < 3; ++axis) append_binary(out, n[axis]);
  append_binary(out, geometry.footprint_m[i]);
}

// The vertex count is known only when every scan is written: the header
// keeps it in a block of fixed size (the count, then a comment of spaces
// that pads it), rewritten at the end.
constexpr std::size_t kPlyCountWidth = 20;  // the digits of 2⁶⁴

std::string ply_vertex_count(std::size_t vertices) {
  const std::string digits = std::to_string(vertices);
  return "element vertex " + digits + "\ncomment" +
         std::string(kPlyCountWidth - digits.size(), ' ') + "\n";
}

constexpr std::string_view kPlyStart =
    "ply\nformat binary_little_endian 1.0\ncomment written by scanbench\n";

std::string ply_header(std::size_t vertices, Channels channels) {
  std::string header(kPlyStart);
  header += ply_vertex_count(vertices);
  header += "property double x\nproperty double y\nproperty double z\n";
  if (channels.intensity) header += "property float intensity\n";
  if (channels.color) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (channels.geometry) {
    header += "property float nx\nproperty float ny\nproperty float nz\nproperty float radius\n";
  }
  return header + "end_header\n";
}

// ---- LAS 1.4 -------------------------------------------------------------

constexpr double kLasScale = 1e-4;  // 0.1 mm
constexpr std::uint16_t kLasHeaderSize = 375;
constexpr std::uint16_t kExtraBytesDescriptorSize = 192;
constexpr std::uint16_t kPointFormat7Size = 36;

// A fixed-size, zero-padded character field.
void append_text(std::string& out, std::string_view text, std::size_t size) {
  std::string field(size, '\0');
  std::copy_n(text.begin(), std::min(text.size(), size), field.begin());
  out += field;
}

struct LasExtent {
  std::size_t points = 0;
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

// The four extra bytes fields of the geometry: one descriptor each.
std::string extra_bytes_vlr() {
  std::string out;
  append_binary(out, std::uint16_t{0});  // reserved
  append_text(out, "LASF_Spec", 16);
  append_binary(out, std::uint16_t{4});  // the extra bytes record
  append_binary(out, static_cast<std::uint16_t>(4 * kExtraBytesDescriptorSize));
  append_text(out, "normal and footprint", 32);
  const std::array<std::pair<const char*, const char*>, 4> fields = {
      {{"NormalX", "unit normal, world x"},
       {"NormalY", "unit normal, world y"},
       {"NormalZ", "unit normal, world z"},
       {"Footprint", "footprint radius [m]"}}};
  for (const auto& [name, description] : fields) {
    std::string d(kExtraBytesDescriptorSize, '\0');
    d[2] = 9;  // data type: float
    std::copy_n(name, std::strlen(name), d.begin() + 4);
    std::copy_n(description, std::strlen(description), d.begin() + 160);
    out += d;
  }
  return out;
}

// The coordinate system as OGC WKT, null-terminated.
std::string wkt_vlr(std::string_view wkt) {
  std::string out;
  append_binary(out, std::uint16_t{0});  // reserved
  append_text(out, "LASF_Projection", 16);
  append_binary(out, std::uint16_t{2112});  // OGC coordinate system WKT
  append_binary(out, static_cast<std::uint16_t>(wkt.size() + 1));
  append_text(out, "coordinate system", 32);
  out += wkt;
  out += '\0';
  return out;
}

std::string las_header(const LasExtent& extent, const std::string& vlrs, std::uint32_t vlr_count,
                       bool extra_bytes, const Eigen::Vector3d& offset) {
  std::string h;
  h += "LASF";
  append_binary(h, std::uint16_t{0});       // file source id
  append_binary(h, std::uint16_t{1 << 4});  // global encoding: WKT (required for formats 6–10)
  append_text(h, "", 16);                   // project GUID
  h += '\x01';
  h += '\x04';  // version 1.4
  append_text(h, "scanbench", 32);
  append_text(h, "scanbench export", 32);
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  append_binary(h, static_cast<std::uint16_t>(utc.tm_yday + 1));
  append_binary(h, static_cast<std::uint16_t>(utc.tm_year + 1900));
  append_binary(h, kLasHeaderSize);
  append_binary(h, static_cast<std::uint32_t>(kLasHeaderSize + vlrs.size()));  // offset to points
  append_binary(h, vlr_count);
  h += '\x07';  // point data record format 7
  append_binary(h, static_cast<std::uint16_t>(kPointFormat7Size + (extra_bytes ? 16 : 0)));
  for (int k = 0; k < 6; ++k) append_binary(h, std::uint32_t{0});  // legacy counts: 0 for 6–10
  for (int axis = 0; axis < 3; ++axis) append_binary(h, kLasScale);
  for (int axis = 0; axis < 3; ++axis) append_binary(h, offset[axis]);
  for (int axis = 0; axis < 3; ++axis) {
    append_binary(h, extent.max[axis]);
    append_binary(h, extent.min[axis]);
  }
  append_binary(h, std::uint64_t{0});  // waveform data
  append_binary(h, std::uint64_t{0});  // first extended VLR
  append_binary(h, std::uint32_t{0});  // extended VLRs
  append_binary(h, static_cast<std::uint64_t>(extent.points));
  append_binary(h, static_cast<std::uint64_t>(extent.points));  // by return: all are first
  for (int k = 1; k < 15; ++k) append_binary(h, std::uint64_t{0});
  assert(h.size() == kLasHeaderSize && "the LAS 1.4 header is 375 bytes");
  return h;
}

std::uint16_t to_u16(double unit) {
  return static_cast<std::uint16_t>(std::lround(std::clamp(unit, 0.0, 1.0) * 65535.0));
}

}  // namespace

struct PointListWriter::State {
  State(const std::filesystem::path& target, PointListFormat f, Channels c)
      : path(target), file(target), format(f), channels(c) {}

  std::filesystem::path path;
  OutputFile file;
  PointListFormat format;
  Channels channels;
  std::size_t points = 0;
  // LAS: the offset, the VLRs, and the quantised extent of what was written.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  std::string vlrs;
  std::uint32_t vlr_count = 0;
  Eigen::Array3<std::int64_t> min_q =
      Eigen::Array3<std::int64_t>::Constant(std::numeric_limits<std::int64_t>::max());
  Eigen::Array3<std::int64_t> max_q =
      Eigen::Array3<std::int64_t>::Constant(std::numeric_limits<std::int64_t>::min());

  void write_ply_point(const Scan& scan, const ScanGeometry* geometry, std::size_t i,
                       const Eigen::Vector3d& p);
  void write_csv_point(const Scan& scan, std::size_t i, const Eigen::Vector3d& p);
  void write_las_point(const Scan& scan, const ScanGeometry* geometry, std::size_t i,
                       const Eigen::Vector3d& p, std::uint16_t source_id);
  std::string las_header_now() const;
};

void PointListWriter::State::write_ply_point(const Scan& scan, const ScanGeometry* geometry,
                                             std::size_t i, const Eigen::Vector3d& p) {
  std::string& out = file.buffer();
  for (int axis = 0; axis < 3; ++axis) append_binary(out, p[axis]);
  if (channels.intensity) append_binary(out, scan.intensity[i]);
  if (channels.color) out.append(reinterpret_cast<const char*>(&scan.rgb[3 * i]), 3);
  if (channels.geometry) append_geometry(out, scan, *geometry, i);
}

void PointListWriter::State::write_csv_point(const Scan& scan, std::size_t i,
                                             const Eigen::Vector3d& p) {
  std::string& out = file.buffer();
  for (int axis = 0; axis < 3; ++axis) {
    if (axis > 0) out += ',';
    append_number(out, p[axis]);
  }
  if (channels.intensity) {
    out += ',';
    append_number(out, scan.intensity[i]);
  }
  for (int c = 0; channels.color && c < 3; ++c) {
    out += ',';
    out += std::to_string(scan.rgb[3 * i + c]);
  }
  out += '\n';
}

void PointListWriter::State::write_las_point(const Scan& scan, const ScanGeometry* geometry,
                                             std::size_t i, const Eigen::Vector3d& p,
                                             std::uint16_t source_id) {
  std::string& out = file.buffer();
  for (int axis = 0; axis < 3; ++axis) {
    const double scaled = (p[axis] - offset[axis]) / kLasScale;
    if (!(std::abs(scaled) < static_cast<double>(std::numeric_limits<std::int32_t>::max()))) {
      throw core::InputError(path.string(), {{}, {}, "scan \"" + scan.name + "\""},
                             "a point lies " + std::to_string(std::abs(p[axis] - offset[axis])) +
                                 " m from the offset of the coordinates, beyond the scans' stored "
                                 "bounds and more than LAS can hold at 0.1 mm");
    }
    const std::int64_t q = std::llround(scaled);
    min_q[axis] = std::min(min_q[axis], q);
    max_q[axis] = std::max(max_q[axis], q);
    append_binary(out, static_cast<std::int32_t>(q));
  }
  append_binary(out, channels.intensity ? to_u16(scan.intensity[i]) : std::uint16_t{0});
  out += '\x11';                        // return 1 of 1
  out += '\0';                          // classification flags, channel, direction, edge
  out += '\0';                          // classification: never classified
  out += '\0';                          // user data
  append_binary(out, std::int16_t{0});  // scan angle
  append_binary(out, source_id);
  append_binary(out, 0.0);  // GPS time
  for (int c = 0; c < 3; ++c) {
    const std::uint16_t v =
        channels.color ? static_cast<std::uint16_t>(scan.rgb[3 * i + c] * 257) : 0;
    append_binary(out, v);
  }
  if (channels.geometry) append_geometry(out, scan, *geometry, i);
}

// The header's bounds are those of the quantised coordinates written.
std::string PointListWriter::State::las_header_now() const {
  LasExtent extent;
  extent.points = points;
  if (points > 0) {
    extent.min = offset + min_q.cast<double>().matrix() * kLasScale;
    extent.max = offset + max_q.cast<double>().matrix() * kLasScale;
  }
  return las_header(extent, vlrs, vlr_count, channels.geometry, offset);
}

PointListWriter::PointListWriter(const std::filesystem::path& path, PointListFormat format,
                                 PointChannels channels, const LasSettings& las) {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (format == PointListFormat::kLas) {
    if (!las.bounds.isEmpty()) {
      offset = las.bounds.min();
      // The largest quantised coordinate must fit a signed 32-bit integer.
      const double span = (las.bounds.max() - offset).maxCoeff();
      if (span / kLasScale > static_cast<double>(std::numeric_limits<std::int32_t>::max())) {
        throw core::InputError(path.string(), {},
                               "the points span " + std::to_string(span) +
                                   " m on an axis: more than LAS can hold at 0.1 mm");
      }
    }
    assert(las.wkt.size() <= kMaxLasWktBytes && "a VLR holds 65535 bytes");
  }
  state_ = std::make_unique<State>(path, format, channels);
  State& s = *state_;
  switch (format) {
    case PointListFormat::kPly:
      s.file.write(ply_header(0, channels));
      break;
    case PointListFormat::kCsv:
      s.file.write(std::string("x,y,z") + (channels.intensity ? ",intensity" : "") +
                   (channels.color ? ",r,g,b" : "") + "\n");
      break;
    case PointListFormat::kLas:
      s.offset = offset;
      s.vlrs = channels.geometry ? extra_bytes_vlr() : std::string();
      if (!las.wkt.empty()) s.vlrs += wkt_vlr(las.wkt);
      s.vlr_count = (channels.geometry ? 1u : 0u) + (las.wkt.empty() ? 0u : 1u);
      s.file.write(s.las_header_now());
      s.file.write(s.vlrs);
      break;
  }
}

PointListWriter::~PointListWriter() = default;

void PointListWriter::add(const Scan& scan, const ScanGeometry* geometry,
                          const std::vector<std::uint8_t>* keep, std::uint16_t source_id,
                          int first_row) {
  State& s = *state_;
  const auto refuse = [&](const char* what) {
    throw core::InputError(
        s.path.string(), {{}, {}, "scan \"" + scan.name + "\""},
        std::string("has no ") + what + ", which the other scans of the file have");
  };
  if (s.channels.intensity && !scan.has_intensity()) refuse("intensity");
  if (s.channels.color && !scan.has_color()) refuse("colour");
  if (s.channels.geometry && geometry == nullptr) refuse("geometry");
  for_each_scan_point(scan, geometry, keep, s.channels.geometry, first_row,
                      [&](std::size_t i, const Eigen::Vector3d& p) {
                        switch (s.format) {
                          case PointListFormat::kPly:
                            s.write_ply_point(scan, geometry, i, p);
                            break;
                          case PointListFormat::kCsv:
                            s.write_csv_point(scan, i, p);
                            break;
                          case PointListFormat::kLas:
                            s.write_las_point(scan, geometry, i, p, source_id);
                            break;
                        }
                        ++s.points;
                        s.file.flush_if_full();
                      });
}

std::size_t PointListWriter::points() const {
  return state_->points;
}

void PointListWriter::commit() {
  State& s = *state_;
  if (s.format == PointListFormat::kPly) {
    s.file.rewrite(kPlyStart.size(), ply_vertex_count(s.points));
  } else if (s.format == PointListFormat::kLas) {
    s.file.rewrite(0, s.las_header_now());
  }
  s.file.commit();
}

namespace {

void write_point_list(const std::filesystem::path& path, PointListFormat format,
                      std::span<const Scan> scans, std::span<const ScanGeometry* const> geometry,
                      std::span<const std::vector<std::uint8_t>* const> keep,
                      std::span<const std::uint16_t> source_ids,
                      const PointListWriter::LasSettings& las) {
  assert((keep.empty() || keep.size() == scans.size()) && "one keep entry per scan");
  const Channels channels = common_channels(scans, geometry);
  PointListWriter writer(path, format, channels, las);
  for (std::size_t s = 0; s < scans.size(); ++s) {
    writer.add(scans[s], channels.geometry ? geometry[s] : nullptr,
               keep.empty() ? nullptr : keep[s], source_ids.empty() ? 0 : source_ids[s]);
  }
  writer.commit();
}

}  // namespace

void write_ply(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep) {
  write_point_list(path, PointListFormat::kPly, scans, geometry, keep, {}, {});
}

void write_csv(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep) {
  write_point_list(path, PointListFormat::kCsv, scans, geometry, keep, {}, {});
}

void write_las(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const std::uint16_t> source_ids,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep, std::string_view wkt) {
  assert(source_ids.size() == scans.size() && "a point source id per scan");
  PointListWriter::LasSettings las;
  las.wkt = std::string(wkt);
  for_each_point(scans, geometry, keep, common_channels(scans, geometry),
                 [&](std::size_t, std::size_t, const Eigen::Vector3d& p) { las.bounds.extend(p); });
  write_point_list(path, PointListFormat::kLas, scans, geometry, keep, source_ids, las);
}

bool looks_like_wkt(std::string_view text) {
  std::size_t k = std::min(text.find_first_not_of(" \t\r\n"), text.size());
  const std::size_t keyword = k;
  while (k < text.size() && (std::isupper(static_cast<unsigned char>(text[k])) ||
                             std::isdigit(static_cast<unsigned char>(text[k])) || text[k] == '_'))
    ++k;
  const std::size_t last = text.find_last_not_of(" \t\r\n");
  return k >= keyword + 4 && k < text.size() && text[k] == '[' && text[last] == ']';
}

}  // namespace scanbench::acquisition

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

struct Channels {
  bool intensity = true;
  bool color = true;
  bool geometry = true;
};

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

// Calls visit(scan index, pixel index, world point) for every exported pixel
// (valid, not a mixed pixel when geometry is exported, and kept when a keep
// mask is given), scan after scan, row-major.
template <typename Visit>
void for_each_point(std::span<const Scan> scans, std::span<const ScanGeometry* const> geometry,
                    std::span<const std::vector<std::uint8_t>* const> keep, Channels channels,
                    Visit&& visit) {
  assert((keep.empty() || keep.size() == scans.size()) && "one keep entry per scan");
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const Scan& scan = scans[s];
    const std::vector<std::uint8_t>* mask = keep.empty() ? nullptr : keep[s];
    assert((mask == nullptr || mask->size() == scan.pixel_count()) && "a byte per pixel");
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::size_t i = scan.index(row, col);
        if (channels.geometry ? !in_model(scan, *geometry[s], i) : !scan.valid[i]) continue;
        if (mask != nullptr && (*mask)[i] == 0) continue;
        visit(s, i, point_in_world(scan, row, col));
      }
    }
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

std::string ply_header(std::size_t vertices, Channels channels) {
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by scanbench\n";
  header += "element vertex " + std::to_string(vertices) + "\n";
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

std::size_t count_exported_points(std::span<const Scan> scans,
                                  std::span<const ScanGeometry* const> geometry,
                                  std::span<const std::vector<std::uint8_t>* const> keep) {
  std::size_t points = 0;
  for_each_point(scans, geometry, keep, common_channels(scans, geometry),
                 [&](std::size_t, std::size_t, const Eigen::Vector3d&) { ++points; });
  return points;
}

void write_ply(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep) {
  const Channels channels = common_channels(scans, geometry);
  OutputFile file(path);
  file.write(ply_header(count_exported_points(scans, geometry, keep), channels));
  for_each_point(scans, geometry, keep, channels,
                 [&](std::size_t s, std::size_t i, const Eigen::Vector3d& p) {
                   const Scan& scan = scans[s];
                   std::string& out = file.buffer();
                   for (int axis = 0; axis < 3; ++axis) append_binary(out, p[axis]);
                   if (channels.intensity) append_binary(out, scan.intensity[i]);
                   if (channels.color)
                     out.append(reinterpret_cast<const char*>(&scan.rgb[3 * i]), 3);
                   if (channels.geometry) append_geometry(out, scan, *geometry[s], i);
                   file.flush_if_full();
                 });
  file.commit();
}

void write_csv(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep) {
  const Channels channels = common_channels(scans, geometry);
  OutputFile file(path);
  file.write(std::string("x,y,z") + (channels.intensity ? ",intensity" : "") +
             (channels.color ? ",r,g,b" : "") + "\n");
  for_each_point(scans, geometry, keep, channels,
                 [&](std::size_t s, std::size_t i, const Eigen::Vector3d& p) {
                   const Scan& scan = scans[s];
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
                   file.flush_if_full();
                 });
  file.commit();
}

void write_las(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const std::uint16_t> source_ids,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep, std::string_view wkt) {
  assert(source_ids.size() == scans.size() && "a point source id per scan");
  const Channels channels = common_channels(scans, geometry);
  LasExtent extent;
  extent.min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  extent.max = -extent.min;
  for_each_point(scans, geometry, keep, channels,
                 [&](std::size_t, std::size_t, const Eigen::Vector3d& p) {
                   ++extent.points;
                   extent.min = extent.min.cwiseMin(p);
                   extent.max = extent.max.cwiseMax(p);
                 });
  if (extent.points == 0) extent.min = extent.max = Eigen::Vector3d::Zero();
  const Eigen::Vector3d offset = extent.min;
  // The largest quantised coordinate must fit a signed 32-bit integer.
  const Eigen::Vector3d span = (extent.max - offset) / kLasScale;
  if (span.maxCoeff() > static_cast<double>(std::numeric_limits<std::int32_t>::max())) {
    throw core::InputError(path.string(), {},
                           "the points span " + std::to_string(span.maxCoeff() * kLasScale) +
                               " m on an axis: more than LAS can hold at 0.1 mm");
  }
  // The header's bounds are those of the quantised coordinates.
  for (int axis = 0; axis < 3; ++axis)
    extent.max[axis] = offset[axis] + std::round(span[axis]) * kLasScale;
  assert(wkt.size() <= kMaxLasWktBytes && "a VLR holds 65535 bytes");
  std::string vlrs = channels.geometry ? extra_bytes_vlr() : std::string();
  if (!wkt.empty()) vlrs += wkt_vlr(wkt);
  const std::uint32_t vlr_count = (channels.geometry ? 1u : 0u) + (wkt.empty() ? 0u : 1u);
  OutputFile file(path);
  file.write(las_header(extent, vlrs, vlr_count, channels.geometry, offset));
  file.write(vlrs);
  for_each_point(
      scans, geometry, keep, channels, [&](std::size_t s, std::size_t i, const Eigen::Vector3d& p) {
        const Scan& scan = scans[s];
        std::string& out = file.buffer();
        for (int axis = 0; axis < 3; ++axis) {
          append_binary(
              out, static_cast<std::int32_t>(std::lround((p[axis] - offset[axis]) / kLasScale)));
        }
        append_binary(out, channels.intensity ? to_u16(scan.intensity[i]) : std::uint16_t{0});
        out += '\x11';                        // return 1 of 1
        out += '\0';                          // classification flags, channel, direction, edge
        out += '\0';                          // classification: never classified
        out += '\0';                          // user data
        append_binary(out, std::int16_t{0});  // scan angle
        append_binary(out, source_ids[s]);
        append_binary(out, 0.0);  // GPS time
        for (int c = 0; c < 3; ++c) {
          const std::uint16_t v =
              channels.color ? static_cast<std::uint16_t>(scan.rgb[3 * i + c] * 257) : 0;
          append_binary(out, v);
        }
        if (channels.geometry) append_geometry(out, scan, *geometry[s], i);
        file.flush_if_full();
      });
  file.commit();
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

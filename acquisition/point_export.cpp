#include "acquisition/point_export.hpp"

#include <algorithm>
#include <bit>
#include <cstring>

#include "acquisition/number_format.hpp"
#include "acquisition/output_file.hpp"

namespace scanbench::acquisition {
namespace {

static_assert(std::endian::native == std::endian::little, "PLY export writes native little-endian");

struct Channels {
  bool intensity = true;
  bool color = true;
};

Channels common_channels(std::span<const Scan> scans) {
  Channels channels;
  for (const Scan& scan : scans) {
    channels.intensity = channels.intensity && scan.has_intensity();
    channels.color = channels.color && scan.has_color();
  }
  return channels;
}

// Calls visit(scan, pixel index, world point) for every valid pixel, scan
// after scan, row-major.
template <typename Visit>
void for_each_valid_point(std::span<const Scan> scans, Visit&& visit) {
  for (const Scan& scan : scans) {
    for (int row = 0; row < scan.rows; ++row) {
      for (int col = 0; col < scan.columns; ++col) {
        const std::size_t i = scan.index(row, col);
        if (scan.valid[i]) visit(scan, i, point_in_world(scan, row, col));
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

std::string ply_header(std::size_t vertices, Channels channels) {
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by scanbench\n";
  header += "element vertex " + std::to_string(vertices) + "\n";
  header += "property double x\nproperty double y\nproperty double z\n";
  if (channels.intensity) header += "property float intensity\n";
  if (channels.color) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  return header + "end_header\n";
}

}  // namespace

void write_ply(const std::filesystem::path& path, std::span<const Scan> scans) {
  const Channels channels = common_channels(scans);
  std::size_t vertices = 0;
  for (const Scan& scan : scans) vertices += count_valid(scan);
  OutputFile file(path);
  file.write(ply_header(vertices, channels));
  for_each_valid_point(scans, [&](const Scan& scan, std::size_t i, const Eigen::Vector3d& p) {
    std::string& out = file.buffer();
    for (int axis = 0; axis < 3; ++axis) append_binary(out, p[axis]);
    if (channels.intensity) append_binary(out, scan.intensity[i]);
    if (channels.color) out.append(reinterpret_cast<const char*>(&scan.rgb[3 * i]), 3);
    file.flush_if_full();
  });
  file.commit();
}

void write_csv(const std::filesystem::path& path, std::span<const Scan> scans) {
  const Channels channels = common_channels(scans);
  OutputFile file(path);
  file.write(std::string("x,y,z") + (channels.intensity ? ",intensity" : "") +
             (channels.color ? ",r,g,b" : "") + "\n");
  for_each_valid_point(scans, [&](const Scan& scan, std::size_t i, const Eigen::Vector3d& p) {
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

}  // namespace scanbench::acquisition

#include "acquisition/point_export.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstring>

#include "acquisition/number_format.hpp"
#include "acquisition/output_file.hpp"

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

}  // namespace

void write_ply(const std::filesystem::path& path, std::span<const Scan> scans,
               std::span<const ScanGeometry* const> geometry,
               std::span<const std::vector<std::uint8_t>* const> keep) {
  const Channels channels = common_channels(scans, geometry);
  std::size_t vertices = 0;
  for_each_point(scans, geometry, keep, channels,
                 [&](std::size_t, std::size_t, const Eigen::Vector3d&) { ++vertices; });
  OutputFile file(path);
  file.write(ply_header(vertices, channels));
  for_each_point(scans, geometry, keep, channels,
                 [&](std::size_t s, std::size_t i, const Eigen::Vector3d& p) {
                   const Scan& scan = scans[s];
                   std::string& out = file.buffer();
                   for (int axis = 0; axis < 3; ++axis) append_binary(out, p[axis]);
                   if (channels.intensity) append_binary(out, scan.intensity[i]);
                   if (channels.color)
                     out.append(reinterpret_cast<const char*>(&scan.rgb[3 * i]), 3);
                   if (channels.geometry) {
                     const Eigen::Vector3f n =
                         (scan.T_world_scan.linear().cast<float>() * geometry[s]->normal[i]);
                     for (int axis = 0; axis < 3; ++axis) append_binary(out, n[axis]);
                     append_binary(out, geometry[s]->footprint_m[i]);
                   }
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

}  // namespace scanbench::acquisition

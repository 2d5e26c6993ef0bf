#include "registration/sample_cloud.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <unordered_set>

namespace scanbench::registration {
namespace {

// Packs a voxel's integer coordinates (21 bits each, ±1 M voxels: 200 km at
// 0.2 m) into one key.
std::uint64_t voxel_key(const Eigen::Vector3f& p, float inverse_voxel) {
  constexpr std::int64_t kOffset = 1 << 20;
  constexpr std::uint64_t kMask = (1u << 21) - 1;
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto cell = static_cast<std::int64_t>(std::floor(p[axis] * inverse_voxel)) + kOffset;
    key = (key << 21) | (static_cast<std::uint64_t>(cell) & kMask);
  }
  return key;
}

// Indices 0, s, 2s, … below `count` with the stride s ≥ 1 that leaves at
// most `max_points` of them.
std::vector<std::size_t> evenly_spaced(std::size_t count, std::size_t max_points) {
  const double stride = std::max(1.0, static_cast<double>(count) / static_cast<double>(max_points));
  std::vector<std::size_t> indices;
  for (double k = 0.0; k < static_cast<double>(count); k += stride) {
    indices.push_back(static_cast<std::size_t>(k));
  }
  return indices;
}

}  // namespace

SampleCloud sample_scan(const PreparedScan& scan, const SampleSettings& settings) {
  assert(settings.voxel_m > 0.0 && settings.max_points > 0);
  const auto inverse_voxel = static_cast<float>(1.0 / settings.voxel_m);
  std::unordered_set<std::uint64_t> occupied;
  std::vector<std::int64_t> firsts;
  for (std::size_t i = 0; i < scan.usable.size(); ++i) {
    if (!scan.usable[i]) continue;
    if (occupied.insert(voxel_key(scan.points[i], inverse_voxel)).second) {
      firsts.push_back(static_cast<std::int64_t>(i));
    }
  }
  SampleCloud cloud;
  for (std::size_t k : evenly_spaced(firsts.size(), settings.max_points)) {
    const std::int64_t pixel = firsts[k];
    cloud.pixels.push_back(pixel);
    cloud.points.push_back(scan.points[static_cast<std::size_t>(pixel)]);
    cloud.normals.push_back(scan.geometry->normal[static_cast<std::size_t>(pixel)]);
  }
  return cloud;
}

SampleCloud thin(const SampleCloud& cloud, std::size_t max_points) {
  assert(max_points > 0);
  SampleCloud thinned;
  for (std::size_t k : evenly_spaced(cloud.size(), max_points)) {
    thinned.points.push_back(cloud.points[k]);
    thinned.normals.push_back(cloud.normals[k]);
    thinned.pixels.push_back(cloud.pixels[k]);
  }
  return thinned;
}

}  // namespace scanbench::registration

#include "render/spatial_tiles.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <numbers>
#include <random>

#include "modeling/lod/octree_cube.hpp"

namespace scanbench::render {

namespace {

Eigen::AlignedBox3f box_of(std::span<const Eigen::Vector3f> positions,
                           std::span<const std::uint32_t> points) {
  Eigen::AlignedBox3f box;
  for (const std::uint32_t p : points) box.extend(positions[p]);
  return box;
}

}  // namespace

std::vector<std::vector<std::uint32_t>> split_into_tiles(std::span<const Eigen::Vector3f> positions,
                                                         std::vector<std::uint32_t> points,
                                                         const TileLimits& limits) {
  assert(limits.max_points >= 1);
  std::vector<std::vector<std::uint32_t>> tiles;
  if (points.empty()) return tiles;
  // Depth first, lower half first: the tiles come out in a fixed order.
  std::vector<std::vector<std::uint32_t>> pending;
  pending.push_back(std::move(points));
  while (!pending.empty()) {
    std::vector<std::uint32_t> part = std::move(pending.back());
    pending.pop_back();
    const Eigen::Vector3f edges = box_of(positions, part).sizes();
    Eigen::Index axis = 0;
    const float longest = edges.maxCoeff(&axis);
    if (part.size() <= limits.max_points && longest <= limits.max_edge_m) {
      tiles.push_back(std::move(part));
      continue;
    }
    if (part.size() < 2) {  // a lone point is as small as a tile gets
      tiles.push_back(std::move(part));
      continue;
    }
    const auto middle = part.begin() + static_cast<std::ptrdiff_t>(part.size() / 2);
    std::nth_element(part.begin(), middle, part.end(), [&](std::uint32_t a, std::uint32_t b) {
      const float pa = positions[a][axis], pb = positions[b][axis];
      return pa < pb || (pa == pb && a < b);
    });
    std::vector<std::uint32_t> upper(middle, part.end());
    part.erase(middle, part.end());
    pending.push_back(std::move(upper));
    pending.push_back(std::move(part));
  }
  return tiles;
}

std::vector<std::uint32_t> order_for_level_of_detail(std::span<const Eigen::Vector3f> positions,
                                                     std::vector<std::uint32_t>& points,
                                                     const Eigen::AlignedBox3f& box) {
  std::vector<std::uint32_t> level_ends(kLodLevels, static_cast<std::uint32_t>(points.size()));
  if (points.empty()) return level_ends;
  constexpr double kCells = 1 << kLodDepth;
  const double edge = std::max(static_cast<double>(box.sizes().maxCoeff()), 1e-9);
  const Eigen::Vector3d corner = box.min().cast<double>();
  std::vector<std::pair<std::uint64_t, std::uint32_t>> coded(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d cell =
        ((positions[points[k]].cast<double>() - corner) * (kCells / edge)).array().floor();
    std::array<std::uint32_t, 3> q{};
    for (int a = 0; a < 3; ++a)
      q[a] = static_cast<std::uint32_t>(std::clamp(cell[a], 0.0, kCells - 1.0));
    coded[k] = {lod::interleave(q, kLodDepth), points[k]};
  }
  std::sort(coded.begin(), coded.end());
  // In Morton order a point is the first of its depth-L cell exactly when
  // its code differs from the previous point's above bit 3 (21 − L): its
  // level is the smallest such L.
  std::vector<std::uint8_t> level(coded.size(), 0);
  std::array<std::uint32_t, kLodLevels> count{};
  for (std::size_t k = 0; k < coded.size(); ++k) {
    if (k > 0) {
      const std::uint64_t differ = coded[k].first ^ coded[k - 1].first;
      const int highest = static_cast<int>(std::bit_width(differ)) - 1;  // -1: the same cell
      level[k] = static_cast<std::uint8_t>(highest < 0 ? kLodLevels - 1 : kLodDepth - highest / 3);
    }
    ++count[level[k]];
  }
  std::uint32_t end = 0;
  std::array<std::uint32_t, kLodLevels> next{};
  for (int l = 0; l < kLodLevels; ++l) {
    next[l] = end;
    end += count[l];
    level_ends[l] = end;
  }
  for (std::size_t k = 0; k < coded.size(); ++k) points[next[level[k]]++] = coded[k].second;
  // Each level shuffled: a prefix cut inside it is spread over the box too.
  std::mt19937 shuffle(static_cast<std::uint32_t>(points.size()));
  std::uint32_t begin = 0;
  for (int l = 0; l < kLodLevels; ++l) {
    std::shuffle(points.begin() + begin, points.begin() + level_ends[l], shuffle);
    begin = level_ends[l];
  }
  return level_ends;
}

NormalCone normal_cone(std::span<const Eigen::Vector3f> normals,
                       std::span<const std::uint32_t> points) {
  NormalCone cone;
  if (points.empty()) return cone;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t known = 0;
  for (const std::uint32_t p : points) {
    if (normals[p].isZero()) continue;
    sum += normals[p].normalized().cast<double>();
    ++known;
  }
  if (known == 0 || sum.norm() < 1e-6 * static_cast<double>(known)) return cone;
  const Eigen::Vector3f axis = sum.normalized().cast<float>();
  float widest = 1.0f;
  for (const std::uint32_t p : points) {
    if (!normals[p].isZero()) widest = std::min(widest, axis.dot(normals[p].normalized()));
  }
  cone.axis = axis;
  // A hair wider than measured: float rounding must not cull a visible point.
  cone.cos_half_angle = std::max(-1.0f, widest - 1e-4f);
  return cone;
}

bool faces_away(const NormalCone& cone, const Eigen::AlignedBox3f& box,
                const Eigen::Vector3f& eye) {
  if (cone.spans_everything() || box.isEmpty()) return false;
  // The box's points are within `radius` of its centre, so the direction to
  // the eye from any of them is within `spread` of the direction from the
  // centre; every normal is within the cone's half angle of its axis.
  const Eigen::Vector3f to_eye = eye - box.center();
  const float distance = to_eye.norm();
  const float radius = 0.5f * box.sizes().norm();
  if (distance <= radius) return false;
  const double spread = std::asin(static_cast<double>(radius / distance));
  const double half = std::acos(static_cast<double>(std::clamp(cone.cos_half_angle, -1.0f, 1.0f)));
  const double angle =
      std::acos(std::clamp(static_cast<double>(cone.axis.dot(to_eye) / distance), -1.0, 1.0));
  return angle > std::numbers::pi / 2 + half + spread;
}

}  // namespace scanbench::render

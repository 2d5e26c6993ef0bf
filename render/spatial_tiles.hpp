// Spatial tiles: what the renderer culls and draws (docs/architecture.md,
// "render model"). A point set is split into boxes small enough to cull on
// their own (the seed partitioned the ground by hand; this splits any large
// object), and each box's points are reordered so that every prefix is an
// even subsample of the whole box: level of detail is a shorter draw (seed
// 000's memory-optimised sequential point tree). A normal cone per tile lets
// the renderer drop tiles that face away from the camera.
//
// Positions are floats relative to one origin (render_model.hpp); indices
// name points in the caller's arrays.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace scanbench::render {

struct TileLimits {
  std::size_t max_points = 32768;  // a draw call's worth
  float max_edge_m = 16.0f;        // so that a frustum can cut a long object
};

// Splits `points` (indices into `positions`) by halving the longest edge of
// each part's box at the median until every part holds at most max_points
// and no edge of its box exceeds max_edge_m (a part of coincident points
// over max_points is halved by count). Every index lands in exactly one
// part; the result depends only on the input. Asserts max_points ≥ 1.
std::vector<std::vector<std::uint32_t>> split_into_tiles(std::span<const Eigen::Vector3f> positions,
                                                         std::vector<std::uint32_t> points,
                                                         const TileLimits& limits);

// The octree depths the level-of-detail order distinguishes; points sharing
// a cell of the deepest all go to the last level, kLodLevels - 1.
inline constexpr int kLodDepth = 21;  // 63 bits of a Morton code
inline constexpr int kLodLevels = kLodDepth + 2;

// Reorders `points` (indices into `positions`, all inside `box`) by level of
// detail over the octree of the cube on `box`'s corner with its longest edge:
// level 0 is one point, level L holds one point for every cell of depth L
// that no coarser level already represents, so the points of levels ≤ L are
// exactly one per occupied depth-L cell. Within a level the order is a fixed
// pseudo-random shuffle, so a prefix cut inside a level is still spread over
// the whole box. Returns the end of each level (kLodLevels entries, the
// last = points.size()).
std::vector<std::uint32_t> order_for_level_of_detail(std::span<const Eigen::Vector3f> positions,
                                                     std::vector<std::uint32_t>& points,
                                                     const Eigen::AlignedBox3f& box);

// The directions a set of normals spans: every known normal is within the
// half angle of the axis. Points without a normal (zero: a surface's edge,
// where the fit failed) go with their tile's surface. A set with no known
// normal spans all directions (cos_half_angle = -1): such a tile is never
// culled by its facing.
struct NormalCone {
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();
  float cos_half_angle = -1.0f;

  bool spans_everything() const { return cos_half_angle <= -1.0f; }
};

NormalCone normal_cone(std::span<const Eigen::Vector3f> normals,
                       std::span<const std::uint32_t> points);

// True when no point of a tile (inside `box`, normals within `cone`) can face
// a camera at `eye`: for every point p and normal n of the tile,
// n · (eye − p) < 0. Conservative: false whenever unsure.
bool faces_away(const NormalCone& cone, const Eigen::AlignedBox3f& box, const Eigen::Vector3f& eye);

}  // namespace scanbench::render

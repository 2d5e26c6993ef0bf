// How the level-of-detail octree distributes its points over its nodes
// (docs/lod.md; seed 000's nested octree, sampled bottom up as
// PotreeConverter 2 does, with a rule that makes the result canonical):
//
//   - a node is a leaf when its region holds at most max_leaf_points points,
//     or at the cube's deepest depth; otherwise it has a child for every
//     octant its region has points in;
//   - a leaf's sample is every point of its region; an inner node's sample is,
//     in every cell of its grid (2^kCellBits cells an edge), the point of
//     least priority (lod_point.hpp) among its children's samples;
//   - a node holds its sample less what its parent took from it.
//
// So the nodes from the root down to depth d together hold one point in
// every occupied cell of depth d's grids: each is an even subsample of the
// model at its resolution. Which point lands where depends on the set of
// points only: not on their order, the threads, or how a build cut the
// work into chunks. Inserting or deleting a point changes only the nodes on
// its path, and splits or joins a leaf that crosses max_leaf_points.
// Within a node the points are in level order: level L holds one point for
// each cell of its grid of 2^L cells an edge that no coarser level
// represents (the last level: points sharing a finest cell with another),
// so every prefix is an even subsample of the node.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "modeling/lod/lod_point.hpp"
#include "modeling/lod/octree_cube.hpp"

namespace scanbench::lod {

// A point while the tree is built: its offset counts from the cube's corner.
struct BuildPoint {
  LodPoint point;
  std::uint64_t priority = 0;  // point_priority of its scan id and pixel
};

inline constexpr int kNodeLevels = kCellBits + 2;

struct OctreeSettings {
  std::size_t max_leaf_points = 20000;
};

// A node while the tree is built.
struct Subtree {
  NodeKey key;
  bool leaf = false;
  std::uint64_t points_below = 0;  // in its region: its own and its descendants'
  std::vector<BuildPoint> sample;  // before its parent takes its share
};

// A node as the store keeps it.
struct BuiltNode {
  NodeKey key;
  bool leaf = false;
  std::uint64_t points_below = 0;
  std::vector<LodPoint> points;  // offsets from the node's corner, in level order
  // points[0, level_ends[L]) are levels 0…L.
  std::array<std::uint32_t, kNodeLevels> level_ends{};
};

// Makes `parent` (its key set) the inner node over `children` (the subtrees
// of its octants that hold points, samples final but for its share): its
// sample is drawn from theirs cell by cell, and leaves them; its
// points_below is theirs summed.
void draw_from_children(const OctreeCube& cube, Subtree& parent, std::span<Subtree> children);

// The node `subtree` becomes once its parent has taken its share (the root:
// as it is): its sample in level order, offsets from the node's corner.
BuiltNode finish_node(const OctreeCube& cube, Subtree&& subtree);

// The subtree of `region` from every point inside it (asserted): each node
// below the region goes to `emit` finished, children before parents; the
// region's own node is returned unfinished, for its parent to take from.
// Deterministic: the result depends on the set of points only.
Subtree build_subtree(const OctreeCube& cube, const NodeKey& region, std::vector<BuildPoint> points,
                      const OctreeSettings& settings, const std::function<void(BuiltNode&&)>& emit);

}  // namespace scanbench::lod

// Editing the level-of-detail octree in place (seed 002: points inserted
// and deleted without a rebuild). The sampling rule (octree_sampling.hpp)
// makes the tree a function of its set of points, so an edit must give the
// tree a build from scratch would give, node for node; and it makes the
// edit local:
//   - a node's sample is its own points and its ancestors' that lie in its
//     region, so any node's sample can be told from the nodes on its path;
//   - a parent's cell lies in one child, so an edit in one child's region
//     changes no sibling.
// An edit therefore rebuilds the smallest regions that hold the edited
// points (a leaf, a new child, or the ancestor that becomes a leaf when
// deletions leave it few enough points) and then draws the nodes on their
// paths up to the root again.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <vector>

#include "modeling/lod/octree_sampling.hpp"

namespace scanbench::lod {

// A node of a tree held in memory for editing: its points in any order,
// offsets from the cube's corner.
struct EditableNode {
  NodeKey key;
  bool leaf = false;
  std::uint64_t points_below = 0;
  std::vector<BuildPoint> points;
};

// A tree by locational code.
using EditableTree = std::map<std::uint64_t, EditableNode>;

struct OctreeEditResult {
  std::set<std::uint64_t> changed;  // nodes whose description or points changed, or new
  std::set<std::uint64_t> removed;  // nodes gone
  std::size_t added_points = 0;
  std::size_t removed_points = 0;  // of those asked for, those the tree held
};

// Point `p` of a node whose corner is `corner` (as the store keeps it:
// offsets from the corner) as an edit holds it: offsets from the cube's
// corner, with its priority. `scan_ids` as for build_editable_tree.
BuildPoint editable_point(const LodPoint& p, const std::array<std::uint64_t, 3>& corner,
                          std::span<const std::int64_t> scan_ids);

// The tree of `points` built from scratch: every node by code.
// `scan_ids[k]` is the project's id of the store's scan k (what the
// points' priorities come from).
EditableTree build_editable_tree(const OctreeCube& cube, const std::vector<BuildPoint>& points,
                                 const OctreeSettings& settings,
                                 std::span<const std::int64_t> scan_ids);

// Removes the points `removed` (found by position and identity: `removed`
// holds each as it was added) and adds `added` (offsets from the cube's
// corner, inside it; identities not in the tree), leaving `tree` as a
// build from scratch of the resulting points gives it. `scan_ids` as for
// build_editable_tree. The regions it builds again are built on `threads`
// workers (core::worker_count); the result does not depend on them.
OctreeEditResult edit_octree(const OctreeCube& cube, const OctreeSettings& settings,
                             EditableTree& tree, std::span<const BuildPoint> added,
                             std::span<const BuildPoint> removed,
                             std::span<const std::int64_t> scan_ids, int threads = 1);

// The nodes whose points edit_octree(cube, settings, tree, added, removed)
// reads, from `skeleton`: the tree's nodes without their points. An edit
// on a tree holding only these nodes (and any others) gives the nodes a
// whole tree would: how a store is edited without reading it whole.
std::set<std::uint64_t> edit_reads(const OctreeCube& cube, const OctreeSettings& settings,
                                   const EditableTree& skeleton, std::span<const BuildPoint> added,
                                   std::span<const BuildPoint> removed);

}  // namespace scanbench::lod

#include "modeling/lod/octree_edit.hpp"

#include <algorithm>
#include <cassert>
#include <optional>
#include <unordered_map>

#include "core/parallel.hpp"

namespace scanbench::lod {
namespace {

// A set of points by identity: a bit a pixel, for the scans that have one
// in it (as large as those scans' grids up to their last such pixel).
class PointSet {
 public:
  void insert(const BuildPoint& p) {
    if (p.point.scan >= bits_.size()) bits_.resize(p.point.scan + std::size_t{1});
    std::vector<std::uint64_t>& words = bits_[p.point.scan];
    if (p.point.pixel / 64 >= words.size()) words.resize(p.point.pixel / 64 + std::size_t{1}, 0);
    words[p.point.pixel / 64] |= std::uint64_t{1} << (p.point.pixel % 64);
  }
  bool contains(const BuildPoint& p) const {
    if (p.point.scan >= bits_.size()) return false;
    const std::vector<std::uint64_t>& words = bits_[p.point.scan];
    return p.point.pixel / 64 < words.size() &&
           ((words[p.point.pixel / 64] >> (p.point.pixel % 64)) & 1u) != 0;
  }

 private:
  std::vector<std::vector<std::uint64_t>> bits_;  // by the store's scan index
};

bool in_region(const OctreeCube& cube, const NodeKey& region, const BuildPoint& p) {
  return cube.node_of(p.point.offset, region.depth) == region;
}

bool is_below(const NodeKey& node, const NodeKey& region) {
  if (node.depth < region.depth) return false;
  const int up = node.depth - region.depth;
  for (int a = 0; a < 3; ++a) {
    if ((node.xyz[a] >> up) != region.xyz[a]) return false;
  }
  return true;
}

// Where the descent of a point at `q` ends: the leaf whose region holds
// it, or the missing child of an inner node (the root of an empty tree).
NodeKey anchor_of(const OctreeCube& cube, const EditableTree& tree,
                  const std::array<std::uint32_t, 3>& q) {
  NodeKey key;
  while (true) {
    const auto found = tree.find(key.code());
    if (found == tree.end() || found->second.leaf) return key;
    key = cube.node_of(q, key.depth + 1);
  }
}

// Which regions an edit rebuilds and which nodes above them it draws
// again: from the nodes' descriptions alone, not their points.
class EditPlanner {
 public:
  EditPlanner(const OctreeCube& cube, const OctreeSettings& settings, const EditableTree& tree)
      : cube_(cube), settings_(settings), tree_(tree) {}

  // The regions, and the nodes above them.
  std::pair<std::set<std::uint64_t>, std::set<std::uint64_t>> plan(
      std::span<const BuildPoint> added, std::span<const BuildPoint> removed) const {
    const std::map<std::uint64_t, std::int64_t> gains = anchor_gains(added, removed);
    std::set<std::uint64_t> regions = outermost(highest_collapsing(gains));
    std::set<std::uint64_t> ancestors;
    for (const std::uint64_t code : regions) {
      for (NodeKey k = NodeKey::from_code(code); k.depth > 0;) {
        k = k.parent();
        ancestors.insert(k.code());
      }
    }
    return {std::move(regions), std::move(ancestors)};
  }

 private:
  // The nodes the edited points' descents end at, each with the points it
  // gains (added less removed). Points come in runs that share a leaf: a
  // point in the last one's anchor ends there too.
  std::map<std::uint64_t, std::int64_t> anchor_gains(std::span<const BuildPoint> added,
                                                     std::span<const BuildPoint> removed) const {
    std::map<std::uint64_t, std::int64_t> gains;
    std::optional<NodeKey> last;
    std::int64_t* gain = nullptr;
    const auto count = [&](const BuildPoint& p, std::int64_t by) {
      if (!last || cube_.node_of(p.point.offset, last->depth) != *last) {
        last = anchor_of(cube_, tree_, p.point.offset);
        gain = &gains[last->code()];
      }
      *gain += by;
    };
    for (const BuildPoint& p : added) count(p, 1);
    for (const BuildPoint& p : removed) count(p, -1);
    return gains;
  }

  // Each anchor raised to its highest ancestor that the edit leaves with
  // few enough points to be a leaf: that ancestor's subtree is rebuilt.
  std::set<std::uint64_t> highest_collapsing(
      const std::map<std::uint64_t, std::int64_t>& gains) const {
    // What each inner node gains: what the anchors below it do.
    std::map<std::uint64_t, std::int64_t> delta;
    for (const auto& [code, gain] : gains) {
      for (NodeKey k = NodeKey::from_code(code); k.depth > 0;) {
        k = k.parent();
        delta[k.code()] += gain;
      }
    }
    std::set<std::uint64_t> raised;
    for (const auto& [code, gain] : gains) {
      NodeKey region = NodeKey::from_code(code);
      for (NodeKey k = region; k.depth > 0;) {
        k = k.parent();
        const EditableNode& node = tree_.at(k.code());
        const auto after = static_cast<std::int64_t>(node.points_below) + delta[k.code()];
        if (after <= static_cast<std::int64_t>(settings_.max_leaf_points)) region = k;
      }
      raised.insert(region.code());
    }
    return raised;
  }

  // Regions below another region are part of it.
  static std::set<std::uint64_t> outermost(const std::set<std::uint64_t>& regions) {
    std::set<std::uint64_t> kept;
    for (const std::uint64_t code : regions) {
      bool inside = false;
      for (NodeKey k = NodeKey::from_code(code); k.depth > 0 && !inside;) {
        k = k.parent();
        inside = regions.count(k.code()) > 0;
      }
      if (!inside) kept.insert(code);
    }
    return kept;
  }

  const OctreeCube& cube_;
  const OctreeSettings& settings_;
  const EditableTree& tree_;
};

class Editor {
 public:
  Editor(const OctreeCube& cube, const OctreeSettings& settings, EditableTree& tree,
         std::span<const std::int64_t> scan_ids, int threads)
      : cube_(cube), settings_(settings), tree_(tree), scan_ids_(scan_ids), threads_(threads) {}

  OctreeEditResult run(std::span<const BuildPoint> added, std::span<const BuildPoint> removed) {
    for (const BuildPoint& p : removed) removed_ids_.insert(p);
    const auto [regions, ancestors] = EditPlanner(cube_, settings_, tree_).plan(added, removed);
    for (const std::uint64_t code : ancestors) old_sample(NodeKey::from_code(code));
    // The added points by the region they fall in (the regions are
    // disjoint, and each added point's descent ends in one).
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> added_to;  // indices in `added`
    int shallowest = cube_.max_depth();
    for (const std::uint64_t code : regions) {
      added_to[code];
      shallowest = std::min(shallowest, NodeKey::from_code(code).depth);
    }
    std::optional<NodeKey> last;  // as the anchors, in runs
    std::vector<std::uint32_t>* to = nullptr;
    for (std::uint32_t i = 0; i < added.size(); ++i) {
      const BuildPoint& p = added[i];
      if (!last || cube_.node_of(p.point.offset, last->depth) != *last) {
        int depth = shallowest;
        auto region = added_to.end();
        while ((region = added_to.find(cube_.node_of(p.point.offset, depth).code())) ==
               added_to.end()) {
          ++depth;
          assert(depth <= cube_.max_depth() && "an added point in no region");
        }
        last = cube_.node_of(p.point.offset, depth);
        to = &region->second;
      }
      to->push_back(i);
    }
    // Each region's points gathered from the tree in turn, its subtree
    // built on the workers, then stored in turn.
    struct Rebuilt {
      NodeKey region;
      std::vector<BuildPoint> points;
      std::vector<EditableNode> nodes;  // below the region
      Subtree top;                      // the region's, unfinished
    };
    std::vector<Rebuilt> rebuilt;
    for (const std::uint64_t code : regions) {
      const NodeKey region = NodeKey::from_code(code);
      std::vector<BuildPoint> points = gather(region, added, added_to[code]);
      if (!points.empty()) rebuilt.push_back({region, std::move(points), {}, {}});
    }
    core::parallel_for_index(static_cast<int>(rebuilt.size()), threads_, [&](int k) {
      Rebuilt& r = rebuilt[static_cast<std::size_t>(k)];
      r.top = build_subtree(cube_, r.region, std::move(r.points), settings_, [&](BuiltNode&& node) {
        r.nodes.push_back({node.key, node.leaf, node.points_below, restored_points(node)});
      });
    });
    for (Rebuilt& r : rebuilt) {
      for (EditableNode& node : r.nodes)
        store_node(node.key, node.leaf, node.points_below, std::move(node.points));
      samples_.emplace(r.region.code(), std::move(r.top));
    }
    redraw_ancestors(ancestors);
    return std::move(result_);
  }

 private:
  // A node's sample before the edit: its points and its ancestors' in its
  // region (memoized; the tree must not have changed yet).
  const std::vector<BuildPoint>& old_sample(const NodeKey& key) {
    const auto found = old_samples_.find(key.code());
    if (found != old_samples_.end()) return found->second;
    std::vector<BuildPoint> sample = tree_.at(key.code()).points;
    if (key.depth > 0) {
      for (const BuildPoint& p : old_sample(key.parent())) {
        if (in_region(cube_, key, p)) sample.push_back(p);
      }
    }
    return old_samples_.emplace(key.code(), std::move(sample)).first->second;
  }

  // The points of region `region` after the edit, among them the added
  // points `inside` it (indices in `added`); the nodes below it leave the
  // tree.
  std::vector<BuildPoint> gather(const NodeKey& region, std::span<const BuildPoint> added,
                                 std::span<const std::uint32_t> inside) {
    std::vector<BuildPoint> points;
    if (region.depth > 0) {
      for (const BuildPoint& p : old_sample(region.parent())) {
        if (in_region(cube_, region, p)) points.push_back(p);
      }
    }
    for (auto at = tree_.begin(); at != tree_.end();) {
      if (!is_below(at->second.key, region)) {
        ++at;
        continue;
      }
      points.insert(points.end(), at->second.points.begin(), at->second.points.end());
      result_.removed.insert(at->first);
      at = tree_.erase(at);
    }
    const std::size_t before = points.size();
    std::erase_if(points, [&](const BuildPoint& p) { return removed_ids_.contains(p); });
    result_.removed_points += before - points.size();
    for (const std::uint32_t i : inside) points.push_back(added[i]);
    result_.added_points += inside.size();
    return points;
  }

  // The nodes above the rebuilt regions, deepest first: each drawn again
  // from its children, of which only those on an edited path changed.
  void redraw_ancestors(const std::set<std::uint64_t>& ancestors) {
    std::vector<NodeKey> order;
    for (const std::uint64_t code : ancestors) order.push_back(NodeKey::from_code(code));
    std::sort(order.begin(), order.end(),
              [](const NodeKey& a, const NodeKey& b) { return a.depth > b.depth; });
    for (const NodeKey& key : order) {
      std::vector<Subtree> children;
      std::vector<bool> edited;
      for (int octant = 0; octant < 8; ++octant) {
        const NodeKey child = key.child(octant);
        if (const auto found = samples_.find(child.code()); found != samples_.end()) {
          children.push_back(std::move(found->second));
          samples_.erase(found);
          edited.push_back(true);
        } else if (const auto node = tree_.find(child.code()); node != tree_.end()) {
          Subtree sibling{child, node->second.leaf, node->second.points_below, node->second.points};
          for (const BuildPoint& p : old_sample(key)) {
            if (in_region(cube_, child, p)) sibling.sample.push_back(p);
          }
          children.push_back(std::move(sibling));
          edited.push_back(false);
        }
      }
      Subtree parent;
      parent.key = key;
      draw_from_children(cube_, parent, children);
      for (std::size_t k = 0; k < children.size(); ++k) {
        if (edited[k])
          store_node(children[k].key, children[k].leaf, children[k].points_below,
                     std::move(children[k].sample));
      }
      samples_.emplace(key.code(), std::move(parent));
    }
    // The root keeps its whole sample.
    if (const auto root = samples_.find(NodeKey{}.code()); root != samples_.end()) {
      store_node(root->second.key, root->second.leaf, root->second.points_below,
                 std::move(root->second.sample));
    }
  }

  void store_node(const NodeKey& key, bool leaf, std::uint64_t below,
                  std::vector<BuildPoint> points) {
    tree_[key.code()] = {key, leaf, below, std::move(points)};
    result_.changed.insert(key.code());
    result_.removed.erase(key.code());
  }

  // A built node's points back in the cube's frame.
  std::vector<BuildPoint> restored_points(const BuiltNode& node) const {
    const std::array<std::uint64_t, 3> corner = cube_.node_corner(node.key);
    std::vector<BuildPoint> points;
    points.reserve(node.points.size());
    for (const LodPoint& p : node.points) points.push_back(editable_point(p, corner, scan_ids_));
    return points;
  }

  const OctreeCube& cube_;
  const OctreeSettings& settings_;
  EditableTree& tree_;
  std::span<const std::int64_t> scan_ids_;
  int threads_;
  PointSet removed_ids_;
  std::map<std::uint64_t, std::vector<BuildPoint>> old_samples_;
  std::map<std::uint64_t, Subtree> samples_;  // new samples of rebuilt regions and redrawn nodes
  OctreeEditResult result_;
};

}  // namespace

BuildPoint editable_point(const LodPoint& p, const std::array<std::uint64_t, 3>& corner,
                          std::span<const std::int64_t> scan_ids) {
  BuildPoint b;
  b.point = p;
  for (int a = 0; a < 3; ++a)
    b.point.offset[a] = static_cast<std::uint32_t>(p.offset[a] + corner[a]);
  b.priority = point_priority(scan_ids[p.scan], p.pixel);
  return b;
}

EditableTree build_editable_tree(const OctreeCube& cube, const std::vector<BuildPoint>& points,
                                 const OctreeSettings& settings,
                                 std::span<const std::int64_t> scan_ids) {
  EditableTree tree;
  edit_octree(cube, settings, tree, points, {}, scan_ids);
  return tree;
}

std::set<std::uint64_t> edit_reads(const OctreeCube& cube, const OctreeSettings& settings,
                                   const EditableTree& skeleton, std::span<const BuildPoint> added,
                                   std::span<const BuildPoint> removed) {
  const auto [regions, ancestors] = EditPlanner(cube, settings, skeleton).plan(added, removed);
  std::set<std::uint64_t> reads = ancestors;
  for (const std::uint64_t code : ancestors) {
    const NodeKey key = NodeKey::from_code(code);
    for (int octant = 0; octant < 8; ++octant) {
      const std::uint64_t child = key.child(octant).code();
      if (skeleton.count(child)) reads.insert(child);
    }
  }
  for (const auto& [code, node] : skeleton) {
    for (const std::uint64_t region : regions) {
      if (is_below(node.key, NodeKey::from_code(region))) {
        reads.insert(code);
        break;
      }
    }
  }
  return reads;
}

OctreeEditResult edit_octree(const OctreeCube& cube, const OctreeSettings& settings,
                             EditableTree& tree, std::span<const BuildPoint> added,
                             std::span<const BuildPoint> removed,
                             std::span<const std::int64_t> scan_ids, int threads) {
  return Editor(cube, settings, tree, scan_ids, threads).run(added, removed);
}

}  // namespace scanbench::lod

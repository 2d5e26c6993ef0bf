#include "modeling/lod/octree_sampling.hpp"

#include <algorithm>
#include <cassert>
#include <numeric>

#include "core/memory.hpp"
#include "core/radix_sort.hpp"

namespace scanbench::lod {
namespace {

// Which cells of a node's grids are taken, level by level: a bit per cell
// of the grid of 2^L cells an edge. Cleared after each node by the cells
// it set, so a node costs its points, not the grids' size.
class TakenCells {
 public:
  TakenCells() {
    for (int level = 0; level <= kCellBits; ++level)
      bits_[level].assign(std::max<std::size_t>(1, (std::size_t{1} << (3 * level)) / 64), 0);
  }
  bool taken(int level, std::uint32_t cell) const {
    return (bits_[level][cell >> 6] >> (cell & 63u)) & 1u;
  }
  void take(int level, std::uint32_t cell) {
    bits_[level][cell >> 6] |= std::uint64_t{1} << (cell & 63u);
  }
  void clear(int level, std::uint32_t cell) { bits_[level][cell >> 6] = 0; }

 private:
  std::array<std::vector<std::uint64_t>, kCellBits + 1> bits_;
};

// The level of each point of a node, given its finest cells in priority
// order: the coarsest level whose cell no point before it took.
std::vector<std::uint8_t> levels_of(std::span<const std::uint32_t> cells) {
  thread_local TakenCells taken;
  std::vector<std::uint8_t> levels(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    int level = 0;
    while (level <= kCellBits && taken.taken(level, cells[i] >> (3 * (kCellBits - level)))) ++level;
    levels[i] = static_cast<std::uint8_t>(level);
    for (int l = level; l <= kCellBits; ++l) taken.take(l, cells[i] >> (3 * (kCellBits - l)));
  }
  for (const std::uint32_t cell : cells) {
    for (int l = 0; l <= kCellBits; ++l) taken.clear(l, cell >> (3 * (kCellBits - l)));
  }
  return levels;
}

// Builds subtrees over points sorted by their Morton code at the deepest
// depth: a node's points are then one run, its children's consecutive runs.
class SubtreeBuilder {
 public:
  // `points` all lie in `region`.
  SubtreeBuilder(const OctreeCube& cube, const NodeKey& region, const OctreeSettings& settings,
                 const std::function<void(BuiltNode&&)>& emit, std::vector<BuildPoint>& points)
      : cube_(cube), settings_(settings), emit_(emit), points_(points) {
    const int depth = cube_.max_depth();
    std::vector<std::pair<std::uint64_t, std::uint32_t>> order, scratch;
    core::reserve_mapped(order, points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i)
      order.emplace_back(cube_.morton_of(points_[i].point.offset, depth),
                         static_cast<std::uint32_t>(i));
    // The codes share the region's digits: only those below them differ.
    const int bits = 3 * std::max(0, depth - region.depth);
    const std::uint64_t below = bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
    core::radix_sort(
        order, scratch, bits,
        [below](const std::pair<std::uint64_t, std::uint32_t>& o) { return o.first & below; });
    std::vector<BuildPoint> sorted;
    core::reserve_mapped(sorted, points_.size());
    core::reserve_mapped(codes_, points_.size());
    for (const auto& [code, i] : order) {
      sorted.push_back(points_[i]);
      codes_.push_back(code);
    }
    points_ = std::move(sorted);
  }

  Subtree build(const NodeKey& key, std::size_t begin, std::size_t end) {
    Subtree node;
    node.key = key;
    node.points_below = end - begin;
    if (end - begin <= settings_.max_leaf_points || key.depth >= cube_.max_depth()) {
      node.leaf = true;
      node.sample.assign(points_.begin() + static_cast<std::ptrdiff_t>(begin),
                         points_.begin() + static_cast<std::ptrdiff_t>(end));
      return node;
    }
    // The octant digit of the children's depth in the deepest codes.
    const int shift = 3 * (cube_.max_depth() - key.depth - 1);
    std::vector<Subtree> children;
    for_each_octant_run(codes_, begin, end, shift, [&](int octant, std::size_t b, std::size_t e) {
      children.push_back(build(key.child(octant), b, e));
    });
    draw_from_children(cube_, node, children);
    for (Subtree& child : children) emit_(finish_node(cube_, std::move(child)));
    return node;
  }

  std::size_t size() const { return points_.size(); }

 private:
  const OctreeCube& cube_;
  const OctreeSettings& settings_;
  const std::function<void(BuiltNode&&)>& emit_;
  std::vector<BuildPoint>& points_;
  std::vector<std::uint64_t> codes_;
};

}  // namespace

void draw_from_children(const OctreeCube& cube, Subtree& parent, std::span<Subtree> children) {
  struct Candidate {
    std::uint32_t cell;
    std::uint32_t child;
    std::uint64_t priority;
    std::uint32_t index;
  };
  std::vector<Candidate> candidates;
  parent.leaf = false;
  parent.points_below = 0;
  for (std::uint32_t k = 0; k < children.size(); ++k) {
    assert(children[k].key.parent() == parent.key && "children of the parent");
    parent.points_below += children[k].points_below;
    const std::vector<BuildPoint>& sample = children[k].sample;
    for (std::uint32_t i = 0; i < sample.size(); ++i) {
      candidates.push_back(
          {cube.cell_in_node(parent.key, sample[i].point.offset), k, sample[i].priority, i});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.cell != b.cell ? a.cell < b.cell : a.priority < b.priority;
  });
  std::vector<std::vector<std::uint8_t>> taken(children.size());
  for (std::size_t k = 0; k < children.size(); ++k) taken[k].assign(children[k].sample.size(), 0);
  parent.sample.clear();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (i > 0 && candidates[i].cell == candidates[i - 1].cell) continue;
    const Candidate& c = candidates[i];
    parent.sample.push_back(children[c.child].sample[c.index]);
    taken[c.child][c.index] = 1;
  }
  for (std::size_t k = 0; k < children.size(); ++k) {
    std::vector<BuildPoint>& sample = children[k].sample;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < sample.size(); ++i) {
      if (!taken[k][i]) sample[kept++] = sample[i];
    }
    sample.resize(kept);
  }
}

BuiltNode finish_node(const OctreeCube& cube, Subtree&& subtree) {
  BuiltNode node;
  node.key = subtree.key;
  node.leaf = subtree.leaf;
  node.points_below = subtree.points_below;
  const std::vector<BuildPoint>& sample = subtree.sample;
  // Priority order, as (priority, index) pairs: cheaper to sort than points.
  // Priorities are distinct (a bijection of the points' identities).
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order(sample.size()), scratch;
  for (std::uint32_t i = 0; i < sample.size(); ++i) order[i] = {sample[i].priority, i};
  core::radix_sort(order, scratch, 64,
                   [](const std::pair<std::uint64_t, std::uint32_t>& o) { return o.first; });
  std::vector<std::uint32_t> cells(sample.size());
  for (std::size_t k = 0; k < sample.size(); ++k)
    cells[k] = cube.cell_in_node(node.key, sample[order[k].second].point.offset);
  const std::vector<std::uint8_t> levels = levels_of(cells);
  // Level order, priority order within a level (a stable counting sort).
  std::array<std::uint32_t, kNodeLevels + 1> starts{};
  for (const std::uint8_t level : levels) ++starts[level + 1];
  std::partial_sum(starts.begin(), starts.end(), starts.begin());
  for (int level = 0; level < kNodeLevels; ++level) node.level_ends[level] = starts[level + 1];
  const std::array<std::uint64_t, 3> corner = cube.node_corner(node.key);
  node.points.resize(sample.size());
  for (std::size_t k = 0; k < sample.size(); ++k) {
    LodPoint p = sample[order[k].second].point;
    for (int a = 0; a < 3; ++a) p.offset[a] = static_cast<std::uint32_t>(p.offset[a] - corner[a]);
    node.points[starts[levels[k]]++] = p;
  }
  return node;
}

Subtree build_subtree(const OctreeCube& cube, const NodeKey& region, std::vector<BuildPoint> points,
                      const OctreeSettings& settings,
                      const std::function<void(BuiltNode&&)>& emit) {
  assert(settings.max_leaf_points >= 1 && "a leaf holds a point at least");
  for ([[maybe_unused]] const BuildPoint& p : points)
    assert(cube.node_of(p.point.offset, region.depth) == region && "points inside the region");
  SubtreeBuilder builder(cube, region, settings, emit, points);
  return builder.build(region, 0, builder.size());
}

}  // namespace scanbench::lod

// The integer geometry of the level-of-detail octree (docs/lod.md): every
// point is quantized once to a grid of 0.1 mm from the model's origin, and
// from there on nodes, cells and their nesting are exact integer arithmetic,
// so the tree a set of points gives does not depend on the order they came
// in, on the threads, or on how the build cut the work.
//
// The root is a cube of 2^edge_bits quanta on the model's lowest corner. A
// node of depth d is the cube of 2^(edge_bits − d) quanta at
// integer coordinates (x, y, z) < 2^d from the root's corner. Each node has
// a grid of 2^kCellBits cells per axis; a node's cell lies inside exactly
// one child (the children's grids have the same count of cells over half
// the edge), which is what lets a parent sample its children cell by cell.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cassert>
#include <cstdint>
#include <optional>
#include <span>

namespace scanbench::lod {

inline constexpr double kQuantumM = 1e-4;  // positions are kept to 0.1 mm
inline constexpr int kCellBits = 7;        // 128 cells along a node's edge
// Depths at most this: a node key (locational code) then fits 61 bits.
inline constexpr int kMaxDepth = 20;

// A node: depth and coordinates at that depth.
struct NodeKey {
  int depth = 0;
  std::array<std::uint32_t, 3> xyz{};

  bool operator==(const NodeKey&) const = default;
  // The locational code: a leading 1 bit, then the Morton interleave of the
  // coordinates (x highest within each triple). Ordered by it, a node's
  // descendants follow it; unique over depths.
  std::uint64_t code() const;
  static NodeKey from_code(std::uint64_t code);
  NodeKey parent() const;
  NodeKey child(int octant) const;  // octant bits: x 4, y 2, z 1
  int octant() const;               // which child of its parent it is
};

// Interleaves the low `bits` bits (at most 21) of x, y and z, x highest
// within a triple: the Morton code.
std::uint64_t interleave(const std::array<std::uint32_t, 3>& xyz, int bits);

// The root cube, in quanta from the model's origin.
struct OctreeCube {
  std::array<std::int64_t, 3> corner{};  // [quanta from the origin]
  int edge_bits = 0;                     // the edge is 2^edge_bits quanta

  // The cube on the lowest corner of `box` (metres from the origin) with
  // the least edge of 2^n quanta that holds it, and at least 2^kCellBits
  // quanta. Empty box: that cube on the origin.
  static OctreeCube enclosing(const Eigen::AlignedBox3d& box);

  // The deepest depth a node of this cube may have: its cells are one
  // quantum, or kMaxDepth.
  int max_depth() const;

  // A point `p` (metres from the origin) in quanta from the corner; none
  // when it lies outside the cube.
  std::optional<std::array<std::uint32_t, 3>> quantize(const Eigen::Vector3d& p) const;

  // The node of depth `depth` holding the point at `q` (quanta from the
  // corner).
  NodeKey node_of(const std::array<std::uint32_t, 3>& q, int depth) const;
  // The same node's Morton code (its coordinates interleaved): in this
  // order a region's points are one run, its children's consecutive runs.
  std::uint64_t morton_of(const std::array<std::uint32_t, 3>& q, int depth) const {
    return interleave(node_of(q, depth).xyz, depth);
  }

  // The edge of a node of depth `depth` [quanta], and its corner [quanta
  // from the root's corner].
  std::uint64_t node_edge(int depth) const { return std::uint64_t{1} << (edge_bits - depth); }
  std::array<std::uint64_t, 3> node_corner(const NodeKey& node) const;

  // The cell of node `node` holding `q`, as the Morton interleave of its
  // coordinates in the node's grid (3·kCellBits bits): the cell of the grid
  // of 2^L cells an edge holding it is this >> 3·(kCellBits − L). Asserts q
  // is in the node.
  std::uint32_t cell_in_node(const NodeKey& node, const std::array<std::uint32_t, 3>& q) const;

  // The node's box in metres from the origin.
  Eigen::AlignedBox3d node_box(const NodeKey& node) const;

  bool operator==(const OctreeCube&) const = default;
};

// Splits [begin, end) of `codes`, Morton codes sorted ascending that share
// the digits above the octant digit at bit `shift`, into the runs of each
// octant: visit(octant, run_begin, run_end) for every run that is not empty,
// in octant order.
template <typename Visit>
void for_each_octant_run(std::span<const std::uint64_t> codes, std::size_t begin, std::size_t end,
                         int shift, Visit&& visit) {
  std::size_t start = begin;
  for (int octant = 0; octant < 8 && start < end; ++octant) {
    const auto stop = std::partition_point(
        codes.begin() + static_cast<std::ptrdiff_t>(start),
        codes.begin() + static_cast<std::ptrdiff_t>(end),
        [&](std::uint64_t code) { return static_cast<int>((code >> shift) & 7u) <= octant; });
    const auto stop_index = static_cast<std::size_t>(stop - codes.begin());
    if (stop_index > start) visit(octant, start, stop_index);
    start = stop_index;
  }
}

}  // namespace scanbench::lod

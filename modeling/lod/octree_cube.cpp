#include "modeling/lod/octree_cube.hpp"

#include <algorithm>
#include <cmath>

namespace scanbench::lod {

namespace {

// The low 21 bits of v spread to every third bit.
std::uint64_t spread_by_three(std::uint64_t v) {
  v &= 0x1fffffu;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

}  // namespace

std::uint64_t interleave(const std::array<std::uint32_t, 3>& xyz, int bits) {
  assert(bits >= 0 && bits <= 21 && "21 bits an axis at most");
  const std::uint32_t mask = bits == 0 ? 0u : (~0u >> (32 - bits));
  return (spread_by_three(xyz[0] & mask) << 2) | (spread_by_three(xyz[1] & mask) << 1) |
         spread_by_three(xyz[2] & mask);
}

std::uint64_t NodeKey::code() const {
  assert(depth >= 0 && depth <= kMaxDepth && "a node within the deepest depth");
  return (std::uint64_t{1} << (3 * depth)) | interleave(xyz, depth);
}

NodeKey NodeKey::from_code(std::uint64_t code) {
  assert(code != 0 && "a locational code has its leading bit");
  NodeKey key;
  while ((code >> (3 * (key.depth + 1))) != 0) ++key.depth;
  for (int b = 0; b < key.depth; ++b) {
    const std::uint64_t triple = code >> (3 * b);
    key.xyz[0] |= static_cast<std::uint32_t>((triple >> 2) & 1u) << b;
    key.xyz[1] |= static_cast<std::uint32_t>((triple >> 1) & 1u) << b;
    key.xyz[2] |= static_cast<std::uint32_t>(triple & 1u) << b;
  }
  return key;
}

NodeKey NodeKey::parent() const {
  assert(depth > 0 && "the root has no parent");
  return {depth - 1, {xyz[0] >> 1, xyz[1] >> 1, xyz[2] >> 1}};
}

NodeKey NodeKey::child(int octant) const {
  return {depth + 1,
          {(xyz[0] << 1) | ((octant >> 2) & 1u), (xyz[1] << 1) | ((octant >> 1) & 1u),
           (xyz[2] << 1) | (octant & 1u)}};
}

int NodeKey::octant() const {
  return static_cast<int>(((xyz[0] & 1u) << 2) | ((xyz[1] & 1u) << 1) | (xyz[2] & 1u));
}

OctreeCube OctreeCube::enclosing(const Eigen::AlignedBox3d& box) {
  OctreeCube cube;
  cube.edge_bits = kCellBits;
  if (box.isEmpty()) return cube;
  std::array<std::int64_t, 3> low{}, high{};
  for (int a = 0; a < 3; ++a) {
    low[a] = static_cast<std::int64_t>(std::floor(box.min()[a] / kQuantumM));
    high[a] = static_cast<std::int64_t>(std::floor(box.max()[a] / kQuantumM));
  }
  // The corner on the box's lowest quanta; the edge the least power of two
  // that reaches past its highest.
  for (int a = 0; a < 3; ++a) {
    cube.corner[a] = low[a];
    while (high[a] - low[a] >= (std::int64_t{1} << cube.edge_bits)) ++cube.edge_bits;
  }
  assert(cube.edge_bits <= 32 && "a model within 400 km");
  return cube;
}

int OctreeCube::max_depth() const {
  return std::clamp(edge_bits - kCellBits, 0, kMaxDepth);
}

std::optional<std::array<std::uint32_t, 3>> OctreeCube::quantize(const Eigen::Vector3d& p) const {
  std::array<std::uint32_t, 3> q{};
  const std::int64_t edge = std::int64_t{1} << edge_bits;
  for (int a = 0; a < 3; ++a) {
    const double quanta = std::floor(p[a] / kQuantumM);
    if (!(quanta >= static_cast<double>(corner[a]) &&
          quanta < static_cast<double>(corner[a] + edge))) {
      return std::nullopt;
    }
    q[a] = static_cast<std::uint32_t>(static_cast<std::int64_t>(quanta) - corner[a]);
  }
  return q;
}

NodeKey OctreeCube::node_of(const std::array<std::uint32_t, 3>& q, int depth) const {
  const int shift = edge_bits - depth;
  // A shift of 32 (the root of a 2^32 cube) would be undefined on uint32.
  const auto at = [shift](std::uint32_t v) {
    return static_cast<std::uint32_t>(std::uint64_t{v} >> shift);
  };
  return {depth, {at(q[0]), at(q[1]), at(q[2])}};
}

std::array<std::uint64_t, 3> OctreeCube::node_corner(const NodeKey& node) const {
  const int shift = edge_bits - node.depth;
  return {std::uint64_t{node.xyz[0]} << shift, std::uint64_t{node.xyz[1]} << shift,
          std::uint64_t{node.xyz[2]} << shift};
}

std::uint32_t OctreeCube::cell_in_node(const NodeKey& node,
                                       const std::array<std::uint32_t, 3>& q) const {
  const int shift = edge_bits - node.depth - kCellBits;
  assert(shift >= 0 && "a node no deeper than the cube's deepest");
  const std::array<std::uint64_t, 3> corner_q = node_corner(node);
  std::array<std::uint32_t, 3> local{};
  for (int a = 0; a < 3; ++a) {
    assert(q[a] >= corner_q[a] && q[a] - corner_q[a] < node_edge(node.depth) && "q in the node");
    local[a] = static_cast<std::uint32_t>((q[a] - corner_q[a]) >> shift);
  }
  return static_cast<std::uint32_t>(interleave(local, kCellBits));
}

Eigen::AlignedBox3d OctreeCube::node_box(const NodeKey& node) const {
  const std::array<std::uint64_t, 3> c = node_corner(node);
  const double edge = static_cast<double>(node_edge(node.depth)) * kQuantumM;
  Eigen::Vector3d low;
  for (int a = 0; a < 3; ++a)
    low[a] = static_cast<double>(corner[a] + static_cast<std::int64_t>(c[a])) * kQuantumM;
  return {low, low + Eigen::Vector3d::Constant(edge)};
}

}  // namespace scanbench::lod

// The level-of-detail octree on hand-built points: its integer geometry,
// the stored point's encodings, and the sampling rule's promises (every
// point once, one point a cell, the same tree whatever the order or the
// cut into chunks, every prefix an even subsample).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "modeling/lod/lod_point.hpp"
#include "modeling/lod/octree_cube.hpp"
#include "modeling/lod/octree_sampling.hpp"

namespace scanbench::lod {
namespace {

TEST(OctreeCube, EnclosesABoxInTheLeastCube) {
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-3.2, 0.5, -1.0), Eigen::Vector3d(12.7, 4.0, 2.5));
  const OctreeCube cube = OctreeCube::enclosing(box);
  const std::int64_t edge = std::int64_t{1} << cube.edge_bits;
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(static_cast<double>(cube.corner[a]) * kQuantumM, box.min()[a]);
    EXPECT_GT(static_cast<double>(cube.corner[a] + edge) * kQuantumM, box.max()[a]);
  }
  EXPECT_LT(static_cast<double>(edge / 2) * kQuantumM, box.sizes().maxCoeff());
  EXPECT_TRUE(cube.quantize(box.min()).has_value());
  EXPECT_TRUE(cube.quantize(box.max()).has_value());
  EXPECT_FALSE(cube.quantize(Eigen::Vector3d(1e4, 0.0, 0.0)).has_value());
  EXPECT_EQ(cube.max_depth(), std::min(cube.edge_bits - kCellBits, kMaxDepth));
}

TEST(OctreeCube, NodeKeysNestAndRoundTrip) {
  const NodeKey key{5, {17, 3, 30}};
  EXPECT_EQ(NodeKey::from_code(key.code()), key);
  EXPECT_EQ(NodeKey::from_code(NodeKey{}.code()), NodeKey{});
  for (int octant = 0; octant < 8; ++octant) {
    EXPECT_EQ(key.child(octant).parent(), key);
    EXPECT_EQ(key.child(octant).octant(), octant);
    EXPECT_GT(key.child(octant).code(), key.code());
  }
  // The Morton code, bit by bit.
  std::mt19937 random(5);
  for (int k = 0; k < 100; ++k) {
    const std::array<std::uint32_t, 3> xyz{static_cast<std::uint32_t>(random()),
                                           static_cast<std::uint32_t>(random()),
                                           static_cast<std::uint32_t>(random())};
    const int bits = k % 22;
    std::uint64_t naive = 0;
    for (int b = bits - 1; b >= 0; --b) {
      for (int a = 0; a < 3; ++a) naive = (naive << 1) | ((xyz[a] >> b) & 1u);
    }
    EXPECT_EQ(interleave(xyz, bits), naive) << bits;
  }
  // A cell of a node lies in exactly one child: the child's cells are
  // half as wide, so a parent cell is 2 × 2 × 2 of them.
  OctreeCube cube;
  cube.edge_bits = 20;
  const std::array<std::uint32_t, 3> q{123456, 654321, 999};
  const NodeKey node = cube.node_of(q, 4);
  const NodeKey child = cube.node_of(q, 5);
  EXPECT_EQ(child.parent(), node);
  const std::uint32_t parent_cell = cube.cell_in_node(node, q);
  EXPECT_EQ(parent_cell >> 18, static_cast<std::uint32_t>(child.octant()));
  EXPECT_EQ(parent_cell & ((1u << 18) - 1), cube.cell_in_node(child, q) >> 3);
}

TEST(LodPoint, UnitVectorsAndHalfFloatsRoundTripClosely) {
  std::mt19937 random(7);
  std::normal_distribution<float> normal;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3f v =
        Eigen::Vector3f(normal(random), normal(random), normal(random)).normalized();
    const Eigen::Vector3d back = decode_unit(encode_unit(v)).cast<double>();
    const double angle =
        std::atan2(back.cross(v.cast<double>()).norm(), back.dot(v.cast<double>()));
    EXPECT_LT(angle, 0.005 * std::numbers::pi / 180.0) << v.transpose();
  }
  for (const Eigen::Vector3f& v :
       {Eigen::Vector3f::UnitZ().eval(), (-Eigen::Vector3f::UnitZ()).eval(),
        Eigen::Vector3f::UnitX().eval()}) {
    EXPECT_LT((decode_unit(encode_unit(v)) - v).norm(), 1e-4f);
  }
  for (const float r : {0.0f, 1e-6f, 0.00123f, 0.25f, 1.0f, 3.3333f, 64.5f, 1000.0f}) {
    EXPECT_NEAR(from_half(to_half(r)), r, std::max(r / 2048.0f, 6e-8f)) << r;
  }
  EXPECT_EQ(from_half(to_half(0.5f)), 0.5f);
  EXPECT_EQ(from_half(to_half(1e9f)), 65504.0f);  // saturates
}

// Points on three planes and a dense cluster, in a cube of 2^16 quanta.
struct OctreeFixture {
  OctreeCube cube;
  std::vector<BuildPoint> points;
};

OctreeFixture octree_fixture(std::size_t count) {
  OctreeFixture f;
  f.cube.edge_bits = 16;  // 6.5 m, 9 depths
  std::mt19937 random(11);
  std::uniform_int_distribution<std::uint32_t> any(0, 65535), cluster(30000, 30400);
  for (std::uint32_t k = 0; k < count; ++k) {
    BuildPoint p;
    switch (k % 4) {
      case 0:
        p.point.offset = {any(random), any(random), 1000};
        break;
      case 1:
        p.point.offset = {20000, any(random), any(random)};
        break;
      case 2:
        p.point.offset = {any(random), 50000, any(random)};
        break;
      default:
        p.point.offset = {cluster(random), cluster(random), cluster(random)};
        break;
    }
    p.point.pixel = k;
    p.point.scan = static_cast<std::uint16_t>(k % 3);
    p.priority = point_priority(k % 3, k);
    f.points.push_back(p);
  }
  return f;
}

std::vector<BuiltNode> whole_tree(const OctreeCube& cube, std::vector<BuildPoint> points,
                                  const OctreeSettings& settings) {
  std::vector<BuiltNode> nodes;
  Subtree root = build_subtree(cube, NodeKey{}, std::move(points), settings,
                               [&](BuiltNode&& node) { nodes.push_back(std::move(node)); });
  nodes.push_back(finish_node(cube, std::move(root)));
  std::sort(nodes.begin(), nodes.end(),
            [](const BuiltNode& a, const BuiltNode& b) { return a.key.code() < b.key.code(); });
  return nodes;
}

bool same_nodes(const std::vector<BuiltNode>& a, const std::vector<BuiltNode>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (!(a[k].key == b[k].key) || a[k].leaf != b[k].leaf ||
        a[k].points_below != b[k].points_below || a[k].points != b[k].points ||
        a[k].level_ends != b[k].level_ends) {
      return false;
    }
  }
  return true;
}

TEST(OctreeSampling, HoldsEveryPointOnceAndOnePointACellAboveTheLeaves) {
  const OctreeFixture f = octree_fixture(40000);
  OctreeSettings settings;
  settings.max_leaf_points = 500;
  const std::vector<BuiltNode> nodes = whole_tree(f.cube, f.points, settings);
  ASSERT_GT(nodes.size(), 20u);
  std::set<std::uint32_t> seen;
  std::map<std::uint64_t, const BuiltNode*> by_code;
  for (const BuiltNode& node : nodes) by_code[node.key.code()] = &node;
  for (const BuiltNode& node : nodes) {
    std::set<std::uint32_t> cells;
    for (const LodPoint& p : node.points) {
      EXPECT_TRUE(seen.insert(p.pixel).second) << "point " << p.pixel << " twice";
      for (int a = 0; a < 3; ++a) EXPECT_LT(p.offset[a], f.cube.node_edge(node.key.depth));
      const std::array<std::uint64_t, 3> corner = f.cube.node_corner(node.key);
      const std::array<std::uint32_t, 3> q{static_cast<std::uint32_t>(p.offset[0] + corner[0]),
                                           static_cast<std::uint32_t>(p.offset[1] + corner[1]),
                                           static_cast<std::uint32_t>(p.offset[2] + corner[2])};
      cells.insert(f.cube.cell_in_node(node.key, q));
    }
    if (!node.leaf) {
      EXPECT_EQ(cells.size(), node.points.size()) << "one point a cell in an inner node";
      EXPECT_GT(node.points_below, settings.max_leaf_points);
    } else {
      EXPECT_TRUE(node.points_below <= settings.max_leaf_points ||
                  node.key.depth == f.cube.max_depth());
    }
    if (node.key.depth > 0) {
      EXPECT_TRUE(by_code.count(node.key.parent().code())) << "orphan";
    }
    EXPECT_EQ(node.level_ends.back(), node.points.size());
  }
  EXPECT_EQ(seen.size(), f.points.size());
  EXPECT_EQ(nodes.front().points_below, f.points.size());
}

TEST(OctreeSampling, NodesDownToADepthSampleEveryOccupiedCellOfItsGrids) {
  const OctreeFixture f = octree_fixture(30000);
  OctreeSettings settings;
  settings.max_leaf_points = 300;
  const std::vector<BuiltNode> nodes = whole_tree(f.cube, f.points, settings);
  for (const int depth : {0, 1, 2, 3}) {
    std::set<std::pair<std::uint64_t, std::uint32_t>> occupied, sampled;
    for (const BuildPoint& p : f.points) {
      const NodeKey node = f.cube.node_of(p.point.offset, depth);
      occupied.insert({node.code(), f.cube.cell_in_node(node, p.point.offset)});
    }
    for (const BuiltNode& n : nodes) {
      if (n.key.depth > depth) continue;
      const std::array<std::uint64_t, 3> corner = f.cube.node_corner(n.key);
      for (const LodPoint& p : n.points) {
        const std::array<std::uint32_t, 3> q{static_cast<std::uint32_t>(p.offset[0] + corner[0]),
                                             static_cast<std::uint32_t>(p.offset[1] + corner[1]),
                                             static_cast<std::uint32_t>(p.offset[2] + corner[2])};
        const NodeKey node = f.cube.node_of(q, depth);
        sampled.insert({node.code(), f.cube.cell_in_node(node, q)});
      }
    }
    // Where a leaf ends above `depth`, all its points are in: still covered.
    for (const auto& cell : occupied) EXPECT_TRUE(sampled.count(cell)) << "depth " << depth;
  }
}

TEST(OctreeSampling, EveryLevelPrefixOfANodeIsOnePointAnOccupiedCell) {
  const OctreeFixture f = octree_fixture(20000);
  OctreeSettings settings;
  settings.max_leaf_points = 4000;
  for (const BuiltNode& node : whole_tree(f.cube, f.points, settings)) {
    for (int level = 0; level <= kCellBits; ++level) {
      std::set<std::uint32_t> all, prefix;
      const int shift = 3 * (kCellBits - level) + 0;
      for (std::size_t k = 0; k < node.points.size(); ++k) {
        const LodPoint& p = node.points[k];
        const int cell_shift = f.cube.edge_bits - node.key.depth - kCellBits;
        const std::array<std::uint32_t, 3> local{
            p.offset[0] >> cell_shift, p.offset[1] >> cell_shift, p.offset[2] >> cell_shift};
        const auto cell = static_cast<std::uint32_t>(interleave(local, kCellBits) >> shift);
        all.insert(cell);
        if (k < node.level_ends[level]) {
          EXPECT_TRUE(prefix.insert(cell).second) << "two in a cell";
        }
      }
      EXPECT_EQ(prefix.size(), all.size()) << "level " << level;
    }
  }
}

TEST(OctreeSampling, GivesOneTreeWhateverTheOrderAndTheCutIntoChunks) {
  const OctreeFixture f = octree_fixture(30000);
  OctreeSettings settings;
  settings.max_leaf_points = 400;
  const std::vector<BuiltNode> reference = whole_tree(f.cube, f.points, settings);
  std::vector<BuildPoint> shuffled = f.points;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
  EXPECT_TRUE(same_nodes(whole_tree(f.cube, shuffled, settings), reference));

  // The root's children built as chunks on their own, the root drawn from them.
  std::map<int, std::vector<BuildPoint>> by_octant;
  for (const BuildPoint& p : shuffled)
    by_octant[f.cube.node_of(p.point.offset, 1).octant()].push_back(p);
  std::vector<BuiltNode> chunked;
  std::vector<Subtree> children;
  for (auto& [octant, points] : by_octant) {
    children.push_back(
        build_subtree(f.cube, NodeKey{}.child(octant), std::move(points), settings,
                      [&](BuiltNode&& node) { chunked.push_back(std::move(node)); }));
  }
  Subtree root;
  draw_from_children(f.cube, root, children);
  for (Subtree& child : children) chunked.push_back(finish_node(f.cube, std::move(child)));
  chunked.push_back(finish_node(f.cube, std::move(root)));
  std::sort(chunked.begin(), chunked.end(),
            [](const BuiltNode& a, const BuiltNode& b) { return a.key.code() < b.key.code(); });
  EXPECT_TRUE(same_nodes(chunked, reference));
}

}  // namespace
}  // namespace scanbench::lod

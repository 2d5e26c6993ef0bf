// Editing the level-of-detail octree in place: random inserts and deletes,
// leaves splitting and joining, give node for node the tree a build from
// scratch gives, and a small edit changes only the nodes on its path.
#include <gtest/gtest.h>

#include <random>

#include "modeling/lod/octree_edit.hpp"

namespace scanbench::lod {
namespace {

// Points on two planes and in a dense cluster, in a cube of 2^16 quanta;
// point k of scan k % 3, pixel k.
std::vector<BuildPoint> edit_pool(std::size_t count) {
  std::mt19937 random(23);
  std::uniform_int_distribution<std::uint32_t> any(0, 65535), cluster(40000, 40300);
  std::vector<BuildPoint> pool;
  for (std::uint32_t k = 0; k < count; ++k) {
    BuildPoint p;
    switch (k % 3) {
      case 0:
        p.point.offset = {any(random), any(random), 3000};
        break;
      case 1:
        p.point.offset = {10000, any(random), any(random)};
        break;
      default:
        p.point.offset = {cluster(random), cluster(random), cluster(random)};
        break;
    }
    p.point.scan = static_cast<std::uint16_t>(k % 3);
    p.point.pixel = k;
    p.priority = point_priority(k % 3, k);
    pool.push_back(p);
  }
  return pool;
}

const std::vector<std::int64_t> kEditScanIds{0, 1, 2};

// Node for node: the same codes, leaves, counts and points.
void expect_same_tree(const EditableTree& edited, const EditableTree& built) {
  ASSERT_EQ(edited.size(), built.size());
  for (const auto& [code, node] : built) {
    const auto found = edited.find(code);
    ASSERT_NE(found, edited.end()) << "node " << code << " missing";
    EXPECT_EQ(found->second.leaf, node.leaf) << code;
    EXPECT_EQ(found->second.points_below, node.points_below) << code;
    const auto ids = [](const EditableNode& n) {
      std::vector<std::pair<std::uint64_t, std::uint32_t>> out;
      for (const BuildPoint& p : n.points) out.emplace_back(p.priority, p.point.pixel);
      std::sort(out.begin(), out.end());
      return out;
    };
    EXPECT_EQ(ids(found->second), ids(node)) << "node " << code;
  }
}

TEST(OctreeEdit, RandomInsertsAndDeletesGiveTheTreeABuildFromScratchGives) {
  OctreeCube cube;
  cube.edge_bits = 16;
  OctreeSettings settings;
  settings.max_leaf_points = 300;
  const std::vector<BuildPoint> pool = edit_pool(40000);
  std::vector<BuildPoint> current(pool.begin(), pool.begin() + 15000);
  std::size_t next = current.size();
  EditableTree tree = build_editable_tree(cube, current, settings, kEditScanIds);
  std::mt19937 random(5);
  for (int round = 0; round < 10; ++round) {
    std::shuffle(current.begin(), current.end(), random);
    // Every fourth round deletes most points: leaves join, inner nodes collapse.
    const std::size_t drop = round % 4 == 3 ? current.size() * 9 / 10 : random() % 2000;
    const std::size_t add = std::min<std::size_t>(random() % 3000, pool.size() - next);
    const std::vector<BuildPoint> removed(current.end() - static_cast<std::ptrdiff_t>(drop),
                                          current.end());
    current.resize(current.size() - drop);
    const std::vector<BuildPoint> added(pool.begin() + static_cast<std::ptrdiff_t>(next),
                                        pool.begin() + static_cast<std::ptrdiff_t>(next + add));
    next += add;
    current.insert(current.end(), added.begin(), added.end());
    const OctreeEditResult result = edit_octree(cube, settings, tree, added, removed, kEditScanIds);
    EXPECT_EQ(result.added_points, add) << round;
    EXPECT_EQ(result.removed_points, drop) << round;
    expect_same_tree(tree, build_editable_tree(cube, current, settings, kEditScanIds));
  }
  // Deleting everything leaves no node.
  edit_octree(cube, settings, tree, {}, current, kEditScanIds);
  EXPECT_TRUE(tree.empty());
}

TEST(OctreeEdit, APointAddedChangesOnlyTheNodesOnItsPath) {
  OctreeCube cube;
  cube.edge_bits = 16;
  OctreeSettings settings;
  settings.max_leaf_points = 300;
  const std::vector<BuildPoint> pool = edit_pool(20001);
  const std::vector<BuildPoint> start(pool.begin(), pool.end() - 1);
  EditableTree tree = build_editable_tree(cube, start, settings, kEditScanIds);
  ASSERT_GT(tree.size(), 100u);
  const OctreeEditResult result =
      edit_octree(cube, settings, tree, std::span(&pool.back(), 1), {}, kEditScanIds);
  // The path (at most one node a depth) and, where its leaf split, the
  // leaf's new children.
  EXPECT_LE(result.changed.size(), static_cast<std::size_t>(cube.max_depth()) + 1 + 8);
  EXPECT_GE(result.changed.size(), 1u);
  expect_same_tree(tree, build_editable_tree(cube, pool, settings, kEditScanIds));
}

}  // namespace
}  // namespace scanbench::lod

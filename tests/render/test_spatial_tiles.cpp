// Spatial tiles: the split respects its limits and loses no point, the
// level-of-detail order makes every level one point per occupied cell and a
// short prefix an even subsample, and normal cones cull only what must face
// away.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <set>

#include "render/spatial_tiles.hpp"

namespace scanbench::render {
namespace {

// A gently waving ground, 120 m × 40 m, a point every 0.25 m.
std::vector<Eigen::Vector3f> ground() {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 480; ++i) {
    for (int j = 0; j < 160; ++j) {
      const float x = 0.25f * static_cast<float>(i), y = 0.25f * static_cast<float>(j);
      points.emplace_back(x, y, 0.3f * std::sin(0.1f * x) + 0.2f * std::cos(0.15f * y));
    }
  }
  return points;
}

std::vector<std::uint32_t> all_of(const std::vector<Eigen::Vector3f>& points) {
  std::vector<std::uint32_t> indices(points.size());
  std::iota(indices.begin(), indices.end(), 0u);
  return indices;
}

TEST(SpatialTiles, TheGroundIsSplitWithinTheLimitsAndEveryPointOnce) {
  const std::vector<Eigen::Vector3f> points = ground();
  const TileLimits limits{5000, 16.0f};
  const auto tiles = split_into_tiles(points, all_of(points), limits);
  EXPECT_GE(tiles.size(), 16u);  // 76 800 points, 8 × 3 boxes of 16 m at least
  std::vector<int> seen(points.size(), 0);
  for (const auto& tile : tiles) {
    EXPECT_LE(tile.size(), limits.max_points);
    Eigen::AlignedBox3f box;
    for (const std::uint32_t p : tile) {
      box.extend(points[p]);
      ++seen[p];
    }
    EXPECT_LE(box.sizes().maxCoeff(), limits.max_edge_m);
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  EXPECT_EQ(split_into_tiles(points, all_of(points), limits), tiles);  // deterministic
}

TEST(SpatialTiles, SmallObjectsAndCoincidentPointsStayWhole) {
  const std::vector<Eigen::Vector3f> post(100, Eigen::Vector3f(1.0f, 2.0f, 3.0f));
  EXPECT_EQ(split_into_tiles(post, all_of(post), {}).size(), 1u);
  const auto halves = split_into_tiles(post, all_of(post), {40, 16.0f});
  EXPECT_EQ(halves.size(), 4u);  // 25 each: halved by count
  EXPECT_TRUE(split_into_tiles(post, {}, {}).empty());
}

TEST(SpatialTiles, EachLevelAddsOnePointPerNewlyOccupiedCell) {
  const std::vector<Eigen::Vector3f> points = ground();
  std::vector<std::uint32_t> order = all_of(points);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  const std::vector<std::uint32_t> ends = order_for_level_of_detail(points, order, box);
  ASSERT_EQ(ends.size(), static_cast<std::size_t>(kLodLevels));
  EXPECT_EQ(ends.back(), points.size());
  EXPECT_EQ(ends[0], 1u);
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(sorted, all_of(points));  // a permutation
  const float edge = box.sizes().maxCoeff();
  for (int level = 1; level <= 9; ++level) {
    // The points of levels ≤ L: one in each occupied depth-L cell.
    const float cell = edge / static_cast<float>(1 << level);
    const auto cell_of = [&](const Eigen::Vector3f& p) {
      const Eigen::Vector3i c =
          ((p - box.min()) / cell).array().floor().cast<int>().cwiseMin((1 << level) - 1);
      return std::tuple(c.x(), c.y(), c.z());
    };
    std::set<std::tuple<int, int, int>> occupied, represented;
    for (const Eigen::Vector3f& p : points) occupied.insert(cell_of(p));
    for (std::uint32_t k = 0; k < ends[level]; ++k) represented.insert(cell_of(points[order[k]]));
    EXPECT_EQ(represented.size(), ends[level]) << "level " << level << ": a cell twice";
    EXPECT_EQ(represented, occupied) << "level " << level;
  }
}

TEST(SpatialTiles, AShortPrefixIsSpreadOverTheWholeBox) {
  const std::vector<Eigen::Vector3f> points = ground();
  std::vector<std::uint32_t> order = all_of(points);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : points) box.extend(p);
  order_for_level_of_detail(points, order, box);
  // 2 % of the points, against 5 m × 5 m cells of the ground: every cell is
  // hit, and none gets more than twice its share.
  const std::size_t prefix = points.size() / 50;
  std::vector<int> hits(24 * 8, 0);
  for (std::size_t k = 0; k < prefix; ++k) {
    const Eigen::Vector3f& p = points[order[k]];
    ++hits[std::min(23, static_cast<int>(p.x() / 5.0f)) * 8 +
           std::min(7, static_cast<int>(p.y() / 5.0f))];
  }
  const double share = static_cast<double>(prefix) / static_cast<double>(hits.size());
  for (const int h : hits) {
    EXPECT_GT(h, 0);
    EXPECT_LT(h, 2.0 * share);
  }
}

TEST(SpatialTiles, NormalConesCullOnlyTilesThatFaceAway) {
  // A floor patch whose normals lean up to 10° from +z.
  std::vector<Eigen::Vector3f> normals;
  for (int k = 0; k < 36; ++k) {
    const float tilt = 10.0f * std::numbers::pi_v<float> / 180.0f;
    const float around = static_cast<float>(k) * std::numbers::pi_v<float> / 18.0f;
    normals.emplace_back(std::sin(tilt) * std::cos(around), std::sin(tilt) * std::sin(around),
                         std::cos(tilt));
  }
  std::vector<std::uint32_t> all(normals.size());
  std::iota(all.begin(), all.end(), 0u);
  const NormalCone cone = normal_cone(normals, all);
  EXPECT_NEAR(cone.axis.z(), 1.0f, 1e-5f);
  EXPECT_NEAR(std::acos(cone.cos_half_angle) * 180.0 / std::numbers::pi, 10.0, 0.05);
  const Eigen::AlignedBox3f patch(Eigen::Vector3f(-1, -1, 0), Eigen::Vector3f(1, 1, 0));
  EXPECT_FALSE(faces_away(cone, patch, {0, 0, 10}));     // from above
  EXPECT_FALSE(faces_away(cone, patch, {30, 0, 0.5f}));  // grazing: some normals see it
  EXPECT_TRUE(faces_away(cone, patch, {0, 0, -10}));     // from below
  EXPECT_TRUE(faces_away(cone, patch, {20, 0, -10}));
  EXPECT_FALSE(faces_away(cone, patch, {0, 0, -0.5f}));  // too near to tell
  normals[3] = Eigen::Vector3f::Zero();                  // an unknown normal goes with the others
  EXPECT_NEAR(normal_cone(normals, all).cos_half_angle, cone.cos_half_angle, 2e-3f);
  const std::vector<Eigen::Vector3f> unknown(4, Eigen::Vector3f::Zero());
  const std::vector<std::uint32_t> four = {0, 1, 2, 3};
  EXPECT_TRUE(normal_cone(unknown, four).spans_everything());
  EXPECT_FALSE(faces_away(normal_cone(unknown, four), patch, {0, 0, -10}));
}

}  // namespace
}  // namespace scanbench::render

// Selecting in the 3D view (render/lasso.hpp): a lasso on the picture
// selects every shown point whose centre it encloses, through every depth
// and in every scan, as per-scan pixel sets.
#include <gtest/gtest.h>

#include "modeling/lod/lod_store.hpp"
#include "render/lasso.hpp"
#include "render/lod_renderer.hpp"
#include "shared_device.hpp"
#include "wall_model.hpp"

namespace scanbench::render {
namespace {

TEST(Lasso, EnclosesByTheEvenOddRule) {
  // A U open at the top: its notch is outside.
  const Lasso u({{0, 0}, {30, 0}, {30, 30}, {20, 30}, {20, 10}, {10, 10}, {10, 30}, {0, 30}});
  EXPECT_TRUE(u.encloses({5, 20}));
  EXPECT_TRUE(u.encloses({25, 20}));
  EXPECT_TRUE(u.encloses({15, 5}));
  EXPECT_FALSE(u.encloses({15, 20}));  // the notch
  EXPECT_FALSE(u.encloses({35, 5}));
  EXPECT_TRUE(u.may_meet(Eigen::AlignedBox2f(Eigen::Vector2f(25, 25), Eigen::Vector2f(40, 40))));
  EXPECT_FALSE(u.may_meet(Eigen::AlignedBox2f(Eigen::Vector2f(31, 0), Eigen::Vector2f(40, 9))));
  EXPECT_TRUE(Lasso({{0, 0}, {10, 10}}).empty());
  EXPECT_FALSE(Lasso({{0, 0}, {10, 10}}).encloses({5, 5}));
}

// The wall's pixels a lasso selects, each of the wall's objects counted.
struct WallSelection {
  std::size_t left = 0, right = 0;  // pixels of objects 1 and 2
};

WallSelection count(const std::map<std::int64_t, std::vector<std::uint32_t>>& selected) {
  WallSelection counts;
  for (const auto& [scan, pixels] : selected) {
    EXPECT_EQ(scan, 1);  // the wall store's one scan
    for (const std::uint32_t pixel : pixels) ++(pixel / 60 >= 40 ? counts.left : counts.right);
  }
  return counts;
}

TEST(LodRendererSelect, SelectsTheShownPointsTheLassoEncloses) {
  test::shared_device();
  LodRenderer renderer(test::wall_store(), {});
  renderer.set_objects(test::wall_tree(/*hide_right=*/true));
  const RenderView view = make_render_view(
      test::camera_at(test::kOrigin + Eigen::Vector3d(0, 0, 1.5)), renderer.header().origin);
  RenderSettings settings;
  // The whole picture: the wall is in view, its right half hidden.
  const WallSelection all =
      count(renderer.select(view, Lasso({{0, 0}, {160, 0}, {160, 120}, {0, 120}}), settings));
  EXPECT_EQ(all.left, 2400u);
  EXPECT_EQ(all.right, 0u);
  // The right half of the picture holds the hidden half of the wall only.
  EXPECT_EQ(
      count(renderer.select(view, Lasso({{80, 0}, {160, 0}, {160, 120}, {80, 120}}), settings))
          .left,
      0u);
  // Shown again, the whole picture selects every point of the wall.
  renderer.set_objects(test::wall_tree());
  const WallSelection both =
      count(renderer.select(view, Lasso({{0, 0}, {160, 0}, {160, 120}, {0, 120}}), settings));
  EXPECT_EQ(both.left + both.right, 4800u);

  // A triangle: exactly the points whose centres project inside it, as
  // every point of the store read and projected says.
  const Lasso triangle({{20, 20}, {150, 60}, {40, 110}});
  const auto selected = renderer.select(view, triangle, settings);
  const lod::LodStore store = lod::LodStore::open(test::wall_store());
  std::vector<std::uint32_t> expected;
  for (const lod::LodNodeInfo& node : store.nodes()) {
    const Eigen::AlignedBox3d box = store.header().cube.node_box(node.key);
    for (const lod::LodPoint& p : store.read_points(node.key)) {
      const Eigen::Vector3d at =
          box.min() + Eigen::Vector3d(p.offset[0], p.offset[1], p.offset[2]) * lod::kQuantumM;
      const auto on_picture = project_to_picture(view, at.cast<float>());
      if (on_picture && triangle.encloses(*on_picture)) expected.push_back(p.pixel);
    }
  }
  std::sort(expected.begin(), expected.end());
  ASSERT_GT(expected.size(), 500u);
  ASSERT_EQ(selected.size(), 1u);
  EXPECT_EQ(selected.at(1), expected);
  // Clipped away, nothing is selected.
  RenderSettings clipped = settings;
  clipped.culling.clipping.box =
      Eigen::AlignedBox3f(Eigen::Vector3f(-1, -1, -1), Eigen::Vector3f(1, 1, 1));
  EXPECT_TRUE(renderer.select(view, triangle, clipped).empty());
}

}  // namespace
}  // namespace scanbench::render

// Selecting in the 3D view (render/lasso.hpp): a lasso on the picture
// selects the shown points whose centres it encloses, those in front or
// through every depth, in every scan, as per-scan pixel sets; a brush
// selects those within a sphere.
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

WallSelection count(const LodSelection& selected) {
  WallSelection counts;
  for (const auto& [scan, pixels] : selected.pixels) {
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
  // Every point, owned or not, through every depth.
  const LodSelectOptions through{.depth_m = kEveryDepth, .open_only = false};
  // The whole picture: the wall is in view, its right half hidden.
  const WallSelection all = count(
      renderer.select(view, Lasso({{0, 0}, {160, 0}, {160, 120}, {0, 120}}), settings, through));
  EXPECT_EQ(all.left, 2400u);
  EXPECT_EQ(all.right, 0u);
  // The right half of the picture holds the hidden half of the wall only.
  EXPECT_EQ(count(renderer.select(view, Lasso({{80, 0}, {160, 0}, {160, 120}, {80, 120}}), settings,
                                  through))
                .left,
            0u);
  // Shown again, the whole picture selects every point of the wall.
  renderer.set_objects(test::wall_tree());
  const WallSelection both = count(
      renderer.select(view, Lasso({{0, 0}, {160, 0}, {160, 120}, {0, 120}}), settings, through));
  EXPECT_EQ(both.left + both.right, 4800u);

  // A triangle: exactly the points whose centres project inside it, as
  // every point of the store read and projected says.
  const Lasso triangle({{20, 20}, {150, 60}, {40, 110}});
  const auto selected = renderer.select(view, triangle, settings, through).pixels;
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
  EXPECT_TRUE(renderer.select(view, triangle, clipped, through).pixels.empty());
  // Points of objects are not to be selected: by default none is.
  EXPECT_EQ(renderer.select(view, triangle, settings).points, 0u);
}

TEST(DepthRaster, ANearerSplatHidesWhatLiesBehindIt) {
  DepthRaster raster(0, 0, 20, 20);
  raster.splat({10.2f, 10.7f}, 5.0f, 3.0f);  // a near splat, 3 px across
  raster.splat({2.5f, 2.5f}, 9.0f, 0.1f);    // a far one, smaller than its pixel
  EXPECT_TRUE(raster.in_front({10.2f, 10.7f}, 5.0f, 0.0f));
  EXPECT_FALSE(raster.in_front({12.5f, 10.5f}, 9.0f, 0.5f));  // behind, within the disc
  EXPECT_TRUE(raster.in_front({12.5f, 10.5f}, 5.3f, 0.5f));   // within the tolerance
  EXPECT_TRUE(raster.in_front({14.5f, 10.5f}, 9.0f, 0.5f));   // beyond the disc
  EXPECT_TRUE(raster.in_front({2.9f, 2.1f}, 9.0f, 0.0f));     // its own pixel
  EXPECT_TRUE(raster.in_front({30.0f, 3.0f}, 9.0f, 0.0f));    // outside the rectangle
}

// The wall, every point still to be segmented, behind a panel 4 m nearer
// (x = 6, y from 0 to 1 m, z from 0.5 to 2 m) owned by object 1.
const std::filesystem::path& panel_store() {
  static const scanbench::test::ScratchDir dir;
  static const std::filesystem::path file = dir / "panel.sbproj.lod";
  static const bool written = [] {
    std::vector<lod::PointToStore> points = test::wall_points(false);
    for (lod::PointToStore& p : points) p.object = 0;
    for (int i = 0; i < 20; ++i) {
      for (int j = 0; j < 30; ++j) {
        lod::PointToStore p;
        p.position = test::kOrigin + Eigen::Vector3d(6.0, 0.05 * i + 0.025, 0.5 + 0.05 * j + 0.025);
        p.normal = -Eigen::Vector3f::UnitX();
        p.radii_m = Eigen::Vector2f(0.04f, 0.04f);
        p.object = 1;
        p.pixel = static_cast<std::uint32_t>(10000 + 30 * i + j);
        points.push_back(p);
      }
    }
    lod::write_lod_store(file, test::kOrigin,
                         {{0, 1, "wall", 0.0f, 1.0f, Eigen::Isometry3d::Identity()}}, points);
    return true;
  }();
  static_cast<void>(written);
  return file;
}

TEST(LodRendererSelect, ALassoTakesWhatIsInFrontAndTheBrushASphere) {
  test::shared_device();
  LodRenderer renderer(panel_store(), {});
  renderer.set_objects(test::wall_tree());
  const RenderView view = make_render_view(
      test::camera_at(test::kOrigin + Eigen::Vector3d(0, 0, 1.5)), renderer.header().origin);
  const RenderSettings settings;
  const Lasso picture({{0, 0}, {160, 0}, {160, 120}, {0, 120}});
  // Through every depth: the whole wall, and the panel when objects count.
  EXPECT_EQ(renderer.select(view, picture, settings, {.depth_m = kEveryDepth}).points, 4800u);
  EXPECT_EQ(
      renderer.select(view, picture, settings, {.depth_m = kEveryDepth, .open_only = false}).points,
      5400u);
  // In front: the panel (an object's) is not taken, and hides the wall
  // behind it. Where the panel lands on the picture, from its corners:
  const auto corner = [&](double y, double z) {
    return *project_to_picture(view,
                               Eigen::Vector3f(6.0f, static_cast<float>(y), static_cast<float>(z)));
  };
  Eigen::AlignedBox2f panel;
  for (const double y : {0.0, 1.0}) {
    for (const double z : {0.5, 2.0}) panel.extend(corner(y, z));
  }
  const LodSelection seen = renderer.select(view, picture, settings, {.sample = 100});
  ASSERT_EQ(seen.pixels.size(), 1u);
  const std::vector<std::uint32_t>& taken = seen.pixels.at(1);
  std::size_t inside = 0, outside = 0;
  for (const lod::PointToStore& p : test::wall_points(false)) {
    const auto at = project_to_picture(view, (p.position - test::kOrigin).cast<float>());
    ASSERT_TRUE(at);
    const bool chosen = std::binary_search(taken.begin(), taken.end(), p.pixel);
    // Clear of the panel's edge by 3 pixels either way:
    const Eigen::AlignedBox2f shrunk(panel.min().array() + 3.0f, panel.max().array() - 3.0f);
    const Eigen::AlignedBox2f grown(panel.min().array() - 3.0f, panel.max().array() + 3.0f);
    if (shrunk.contains(*at)) {
      EXPECT_FALSE(chosen) << "pixel " << p.pixel << " lies behind the panel";
      ++inside;
    } else if (!grown.contains(*at)) {
      EXPECT_TRUE(chosen) << "pixel " << p.pixel << " is in view";
      ++outside;
    }
  }
  EXPECT_GT(inside, 100u);
  // Down to 4.5 m behind the nearest surface: the wall behind the panel
  // (4 m behind it) too; down to 3 m, not.
  EXPECT_EQ(renderer.select(view, picture, settings, {.depth_m = 4.5f}).points, 4800u);
  EXPECT_EQ(renderer.select(view, picture, settings, {.depth_m = 3.0f}).points, taken.size());
  EXPECT_GT(outside, 2500u);
  EXPECT_LE(seen.sample.size(), 100u);
  EXPECT_GE(seen.sample.size(), 50u);
  // The brush: a 0.3 m sphere on the wall takes the samples within it.
  const Eigen::Vector3f centre(10.0f, -1.0f, 1.0f);
  const LodSelection ball = renderer.select_sphere(centre, 0.3f, settings);
  std::size_t expected = 0;
  for (const lod::PointToStore& p : test::wall_points(false))
    expected += ((p.position - test::kOrigin).cast<float>() - centre).norm() <= 0.3f;
  EXPECT_GT(expected, 50u);
  EXPECT_NEAR(static_cast<double>(ball.points), static_cast<double>(expected), 2.0);
}

}  // namespace
}  // namespace scanbench::render

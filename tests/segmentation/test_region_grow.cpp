#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "segmentation/constraints.hpp"
#include "segmentation/pixel_set.hpp"
#include "segmentation/region_grow.hpp"
#include "segmentation/room_scene.hpp"
#include "segmentation/segmentation_grid.hpp"

namespace scanbench::segmentation {
namespace {

using test::shared_room;

const SegmentationGrid& room_grid() {
  static const SegmentationGrid grid = [] {
    GridSettings settings;
    settings.threads = 1;
    return prepare_grid(shared_room().scan, shared_room().geometry, settings);
  }();
  return grid;
}

// The usable pixels of `object`, as a set.
PixelSet truth_pixels(std::uint8_t object) {
  PixelSet pixels;
  const auto& truth = shared_room().truth;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i] == object && room_grid().usable[i])
      pixels.push_back(static_cast<std::uint32_t>(i));
  }
  return pixels;
}

struct Agreement {
  double recall = 0;         // share of the object's pixels in the region
  std::size_t foreign = 0;   // region pixels of another object
  double foreign_share = 0;  // of the region
};

Agreement agreement(const PixelSet& region, std::uint8_t object) {
  const PixelSet truth = truth_pixels(object);
  Agreement a;
  a.recall =
      static_cast<double>(intersect(region, truth).size()) / static_cast<double>(truth.size());
  a.foreign = subtract(region, truth).size();
  a.foreign_share =
      static_cast<double>(a.foreign) / static_cast<double>(std::max<std::size_t>(1, region.size()));
  return a;
}

// The pixel whose direction is nearest to azimuth / elevation [deg].
std::size_t pixel_at(double azimuth_deg, double elevation_deg) {
  const int col = static_cast<int>(std::lround((azimuth_deg + 180.0) / 0.5 - 0.5)) % 720;
  const int row = static_cast<int>(std::lround((30.0 - elevation_deg) / 0.5));
  return shared_room().scan.index(row, col);
}

std::vector<std::uint8_t> everything_open() {
  return open_pixels(room_grid(), Constraints{}, {});
}

GrowResult grow(std::size_t seed, Channel channel, const std::vector<std::uint8_t>& open) {
  RegionGrower grower(room_grid());
  return grower.grow(seed, default_grow_settings(channel), open);
}

TEST(RegionGrow, NormalChannelTakesTheWallAndStopsAtTheCreasesAndTheRecess) {
  ASSERT_EQ(shared_room().truth[pixel_at(-20, 0)], test::kWallPlusX);
  const GrowResult wall = grow(pixel_at(-20, 0), Channel::kNormal, everything_open());
  ASSERT_TRUE(wall.seed_open);
  // The poster is flush with the wall: the normal channel cannot see it.
  const Agreement a =
      agreement(subtract(wall.pixels, truth_pixels(test::kPoster)), test::kWallPlusX);
  // Pixels on a crease see both surfaces; the object is the one under the
  // beam centre. Nothing beyond them: no floor, no pane.
  EXPECT_LT(a.foreign_share, 0.01);
  EXPECT_EQ(intersect(wall.pixels, truth_pixels(test::kWindow)).size(), 0u);
  // Only the reveals, seen edge-on, stay out.
  EXPECT_GT(a.recall, 0.98);
}

TEST(RegionGrow, ThePaneBehindTheRecessIsItsOwnRegionOnEveryGeometricChannel) {
  const GrowResult pane = grow(pixel_at(0, 8), Channel::kNormal, everything_open());
  const Agreement a = agreement(pane.pixels, test::kWindow);
  EXPECT_EQ(a.foreign, 0u);
  EXPECT_EQ(a.recall, 1.0);
  // The range channel follows the pane round its creases onto the reveals,
  // but not across the depth jump where they meet the façade.
  const GrowResult surface = grow(pixel_at(0, 8), Channel::kRange, everything_open());
  EXPECT_EQ(agreement(surface.pixels, test::kWindow).recall, 1.0);
  for (const std::uint32_t p : subtract(surface.pixels, truth_pixels(test::kWindow))) {
    EXPECT_GT(room_grid().point[p].x(), 5.001f) << "pixel " << p << " is on the façade";
  }
}

TEST(RegionGrow, ColorAndIntensityFindThePosterFlushWithTheWall) {
  const std::size_t seed = pixel_at(36, 0);
  ASSERT_EQ(shared_room().truth[seed], test::kPoster);
  for (const Channel channel : {Channel::kColor, Channel::kIntensity}) {
    const GrowResult poster = grow(seed, channel, everything_open());
    const Agreement a = agreement(poster.pixels, test::kPoster);
    EXPECT_EQ(a.foreign, 0u) << channel_name(channel);
    EXPECT_EQ(a.recall, 1.0) << channel_name(channel);
  }
}

TEST(RegionGrow, RangeChannelFollowsTheSurfaceAcrossCreasesButNotDepthJumps) {
  // The floor meets the walls without a depth jump: range continuity alone
  // joins them, which is what the normal channel is for.
  const GrowResult room = grow(pixel_at(0, -45), Channel::kRange, everything_open());
  EXPECT_GT(agreement(room.pixels, test::kFloor).recall, 0.99);
  EXPECT_GT(agreement(room.pixels, test::kWallMinusY).recall, 0.9);
  EXPECT_LT(agreement(room.pixels, test::kWindow).recall, 0.05);
}

TEST(RegionGrow, RegionsWrapAroundTheSeam) {
  const GrowResult wall = grow(pixel_at(179, 5), Channel::kNormal, everything_open());
  const Agreement a = agreement(wall.pixels, test::kWallMinusX);
  EXPECT_LT(a.foreign_share, 0.01);
  EXPECT_GT(a.recall, 0.99);
  const auto& scan = shared_room().scan;
  const auto column_of = [&](std::uint32_t p) { return static_cast<int>(p % scan.columns); };
  EXPECT_TRUE(std::any_of(wall.pixels.begin(), wall.pixels.end(),
                          [&](std::uint32_t p) { return column_of(p) < 10; }));
  EXPECT_TRUE(std::any_of(wall.pixels.begin(), wall.pixels.end(),
                          [&](std::uint32_t p) { return column_of(p) > 710; }));
}

TEST(RegionGrow, TakenAndClosedPixelsAreLeftAlone) {
  std::vector<std::uint8_t> taken(shared_room().truth.size(), 0);
  for (const std::uint32_t p : truth_pixels(test::kWallPlusX)) taken[p] = 1;
  const std::vector<std::uint8_t> open = open_pixels(room_grid(), Constraints{}, taken);
  // The seed itself is taken: nothing grows.
  const GrowResult none = grow(pixel_at(-20, 0), Channel::kNormal, open);
  EXPECT_FALSE(none.seed_open);
  EXPECT_TRUE(none.pixels.empty());
  // The poster is flush with its wall: the range channel reaches the wall
  // only through taken pixels.
  const GrowResult poster = grow(pixel_at(36, 0), Channel::kRange, open);
  const Agreement a = agreement(poster.pixels, test::kPoster);
  EXPECT_EQ(a.foreign, 0u);
  EXPECT_EQ(a.recall, 1.0);
}

TEST(RegionGrow, TheRangeToleranceDecidesWhichStepsAreSurface) {
  // The pane lies 0.3 m behind the façade, about ten footprints at 5 m.
  const GrowResult tight = grow(pixel_at(0, 20), Channel::kRange, everything_open());
  EXPECT_EQ(intersect(tight.pixels, truth_pixels(test::kWindow)).size(), 0u);
  GrowSettings loose = default_grow_settings(Channel::kRange);
  loose.tolerance = 20.0;
  RegionGrower grower(room_grid());
  const GrowResult across = grower.grow(pixel_at(0, 20), loose, everything_open());
  EXPECT_EQ(agreement(across.pixels, test::kWindow).recall, 1.0);
}

TEST(RegionGrow, ANormalSeedWithoutANormalIsItsRegionAlone) {
  const SegmentationGrid& grid = room_grid();
  std::size_t seed = grid.normal.size();
  for (std::size_t i = 0; i < grid.normal.size(); ++i) {
    if (grid.usable[i] && grid.normal[i].squaredNorm() == 0.0f) {
      seed = i;
      break;
    }
  }
  ASSERT_LT(seed, grid.normal.size()) << "the room has pixels without a normal at its edges";
  const GrowResult alone = grow(seed, Channel::kNormal, everything_open());
  EXPECT_TRUE(alone.seed_lacks_channel);
  EXPECT_EQ(alone.pixels, PixelSet{static_cast<std::uint32_t>(seed)});
}

TEST(RegionGrow, TheLimitStopsTheRegion) {
  GrowSettings settings = default_grow_settings(Channel::kNormal);
  settings.max_pixels = 100;
  RegionGrower grower(room_grid());
  const GrowResult limited = grower.grow(pixel_at(-20, 0), settings, everything_open());
  EXPECT_TRUE(limited.reached_limit);
  EXPECT_EQ(limited.pixels.size(), 100u);
  EXPECT_TRUE(std::is_sorted(limited.pixels.begin(), limited.pixels.end()));
}

TEST(RegionGrow, RepeatedClicksOnOneGrowerGiveTheSameRegions) {
  RegionGrower grower(room_grid());
  const std::vector<std::uint8_t> open = everything_open();
  const GrowSettings settings = default_grow_settings(Channel::kColor);
  const PixelSet first = grower.grow(pixel_at(36, 0), settings, open).pixels;
  grower.grow(pixel_at(-20, 0), settings, open);
  EXPECT_EQ(grower.grow(pixel_at(36, 0), settings, open).pixels, first);
}

TEST(RegionGrow, AChannelTheScanLacksGrowsNothingButTheSeed) {
  acquisition::Scan bare = shared_room().scan;
  bare.rgb.clear();
  bare.intensity.clear();
  const SegmentationGrid grid = prepare_grid(bare, shared_room().geometry, GridSettings{});
  RegionGrower grower(grid);
  const std::vector<std::uint8_t> open = open_pixels(grid, Constraints{}, {});
  for (const Channel channel : {Channel::kColor, Channel::kIntensity}) {
    const GrowResult result = grower.grow(pixel_at(36, 0), default_grow_settings(channel), open);
    EXPECT_TRUE(result.seed_lacks_channel);
    EXPECT_EQ(result.pixels, PixelSet{static_cast<std::uint32_t>(pixel_at(36, 0))});
  }
}

TEST(SegmentationGrid, ChannelNamesRoundTrip) {
  for (const Channel channel :
       {Channel::kRange, Channel::kColor, Channel::kIntensity, Channel::kNormal}) {
    EXPECT_EQ(channel_from_name(channel_name(channel)), channel);
  }
  EXPECT_FALSE(channel_from_name("colour").has_value());
}

TEST(SegmentationGrid, LabOfWhiteBlackAndRed) {
  const auto white = srgb_to_lab(255, 255, 255);
  EXPECT_NEAR(white[0], 100.0f, 0.05f);
  EXPECT_NEAR(white[1], 0.0f, 0.05f);
  EXPECT_NEAR(white[2], 0.0f, 0.05f);
  EXPECT_NEAR(srgb_to_lab(0, 0, 0)[0], 0.0f, 1e-4f);
  const auto red = srgb_to_lab(255, 0, 0);  // reference: L 53.24, a 80.09, b 67.20
  EXPECT_NEAR(red[0], 53.24f, 0.1f);
  EXPECT_NEAR(red[1], 80.09f, 0.2f);
  EXPECT_NEAR(red[2], 67.20f, 0.2f);
}

}  // namespace
}  // namespace scanbench::segmentation

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "segmentation/constraints.hpp"
#include "segmentation/pixel_set.hpp"
#include "segmentation/region_grow.hpp"
#include "segmentation/room_scene.hpp"

namespace scanbench::segmentation {
namespace {

using V = Eigen::Vector2d;

// A flat, featureless grid: every pixel usable, one plane facing the scanner,
// so only the constraints shape a region.
SegmentationGrid flat_grid(int rows, int columns, bool wraps) {
  SegmentationGrid grid;
  grid.shape = {rows, columns, wraps};
  const std::size_t n = grid.shape.pixel_count();
  grid.usable.assign(n, 1);
  grid.normal.assign(n, Eigen::Vector3f(-1, 0, 0));
  grid.footprint_m.assign(n, 0.01f);
  grid.point.resize(n);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < columns; ++c)
      grid.point[grid.shape.index(r, c)] = {10.0f, 0.01f * c, -0.01f * r};
  }
  return grid;
}

std::vector<std::uint8_t> empty_mask(const GridShape& shape) {
  return std::vector<std::uint8_t>(shape.pixel_count(), 0);
}

TEST(FillPolygon, TakesThePixelCentresInsideARectangle) {
  const GridShape shape{10, 20, false};
  std::vector<std::uint8_t> mask = empty_mask(shape);
  fill_polygon(shape, {V(2.5, 1.5), V(6.5, 1.5), V(6.5, 4.5), V(2.5, 4.5)}, 1, mask);
  for (int r = 0; r < 10; ++r) {
    for (int c = 0; c < 20; ++c) {
      const bool inside = r >= 2 && r <= 4 && c >= 3 && c <= 6;
      EXPECT_EQ(mask[shape.index(r, c)], inside ? 1 : 0) << r << "," << c;
    }
  }
}

TEST(FillPolygon, ALassoAcrossTheSeamCoversBothEdgesOfAWrappingGrid) {
  const GridShape wrapping{10, 100, true};
  std::vector<std::uint8_t> mask = empty_mask(wrapping);
  fill_polygon(wrapping, {V(95.5, 2.5), V(104.5, 2.5), V(104.5, 5.5), V(95.5, 5.5)}, 1, mask);
  EXPECT_EQ(from_mask(mask).size(), 9u * 3u);
  EXPECT_EQ(mask[wrapping.index(4, 99)], 1);
  EXPECT_EQ(mask[wrapping.index(4, 0)], 1);
  EXPECT_EQ(mask[wrapping.index(4, 4)], 1);
  EXPECT_EQ(mask[wrapping.index(4, 5)], 0);
  // The same lasso on a grid that does not wrap is clipped at its edge.
  const GridShape clipped{10, 100, false};
  std::vector<std::uint8_t> clipped_mask = empty_mask(clipped);
  fill_polygon(clipped, {V(95.5, 2.5), V(104.5, 2.5), V(104.5, 5.5), V(95.5, 5.5)}, 1,
               clipped_mask);
  EXPECT_EQ(from_mask(clipped_mask).size(), 4u * 3u);
}

TEST(FillPolygon, DegenerateLassosCoverNothing) {
  const GridShape shape{10, 20, false};
  std::vector<std::uint8_t> mask = empty_mask(shape);
  fill_polygon(shape, {V(1, 1), V(8, 8)}, 1, mask);
  fill_polygon(shape, {V(1, 1), V(8, 8), V(4.5, 4.5)}, 1, mask);  // collinear
  EXPECT_TRUE(from_mask(mask).empty());
}

TEST(DrawBarrier, IsAFourConnectedChainFromEndToEnd) {
  const GridShape shape{50, 50, false};
  std::vector<std::uint8_t> mask = empty_mask(shape);
  draw_barrier(shape, {V(3, 2), V(40, 31)}, 1, mask);
  const PixelSet line = from_mask(mask);
  EXPECT_EQ(line.size(), 37u + 29u + 1u);  // every step moves along one axis only
  EXPECT_EQ(mask[shape.index(2, 3)], 1);
  EXPECT_EQ(mask[shape.index(31, 40)], 1);
  EXPECT_EQ(separate(GridShape{50, 50, false}, line).size(), 1u);
}

// Region growing on a flat grid from the left of a barrier never reaches
// its right, for barriers at every slope, including the seam.
TEST(DrawBarrier, NoEightConnectedStepLeaksThroughAtAnySlope) {
  const SegmentationGrid grid = flat_grid(60, 120, true);
  RegionGrower grower(grid);
  for (const double dx : {0.0, 0.3, 1.0, 1.7, 5.0, 40.0}) {
    // A closed loop of four slanted barriers around the pixel (30, 60).
    Constraints constraints;
    constraints.barriers = {{V(40 - dx, 10), V(80 + dx, 12)},
                            {V(80 + dx, 12), V(81 - dx, 50)},
                            {V(81 - dx, 50), V(41 + dx, 49)},
                            {V(41 + dx, 49), V(40 - dx, 10)}};
    const std::vector<std::uint8_t> open = open_pixels(grid, constraints, {});
    const GrowResult inside =
        grower.grow(grid.shape.index(30, 60), default_grow_settings(Channel::kNormal), open);
    ASSERT_TRUE(inside.seed_open);
    EXPECT_LT(inside.pixels.size(), 60u * 50u) << "leaked at dx " << dx;
    for (const std::uint32_t p : inside.pixels) {
      EXPECT_GE(p / 120, 10u) << "leaked at dx " << dx;
      EXPECT_LE(p / 120, 50u) << "leaked at dx " << dx;
    }
  }
  // Across the seam: a barrier ring around column 0 keeps the region off the rest.
  Constraints seam;
  seam.barriers = {{V(-5, 20), V(5, 20), V(5, 40), V(-5, 40), V(-5, 20)}};
  const GrowResult ring =
      grower.grow(grid.shape.index(30, 0), default_grow_settings(Channel::kNormal),
                  open_pixels(grid, seam, {}));
  EXPECT_EQ(ring.pixels.size(), 9u * 19u);  // columns 116…119, 0…4; rows 21…39
}

TEST(OpenPixels, TheLassoBoundsTheRegionAndTakenPixelsStayOut) {
  const SegmentationGrid grid = flat_grid(40, 80, false);
  Constraints constraints;
  constraints.lasso = {V(9.5, 4.5), V(30.5, 4.5), V(30.5, 20.5), V(9.5, 20.5)};
  std::vector<std::uint8_t> taken(grid.shape.pixel_count(), 0);
  for (int r = 0; r < 40; ++r) taken[grid.shape.index(r, 20)] = 1;  // a taken column
  const std::vector<std::uint8_t> open = open_pixels(grid, constraints, taken);
  RegionGrower grower(grid);
  const GrowResult left =
      grower.grow(grid.shape.index(10, 12), default_grow_settings(Channel::kNormal), open);
  EXPECT_EQ(left.pixels.size(), 10u * 16u);  // columns 10…19, rows 5…20
  const GrowResult outside =
      grower.grow(grid.shape.index(30, 12), default_grow_settings(Channel::kNormal), open);
  EXPECT_FALSE(outside.seed_open);
}

}  // namespace
}  // namespace scanbench::segmentation

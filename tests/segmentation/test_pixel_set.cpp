#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "segmentation/pixel_set.hpp"

namespace scanbench::segmentation {
namespace {

TEST(PixelSet, RadixSortAgreesWithStdSort) {
  std::mt19937 random(7);
  for (const std::size_t size : {0u, 1u, 255u, 256u, 10000u}) {
    std::vector<std::uint32_t> values(size);
    for (auto& v : values) v = random();
    std::vector<std::uint32_t> expected = values;
    std::sort(expected.begin(), expected.end());
    sort_pixels(values);
    EXPECT_EQ(values, expected) << size;
  }
}

TEST(PixelSet, SetOperations) {
  const PixelSet a = {1, 3, 5, 7}, b = {3, 4, 5};
  EXPECT_EQ(unite(a, b), (PixelSet{1, 3, 4, 5, 7}));
  EXPECT_EQ(subtract(a, b), (PixelSet{1, 7}));
  EXPECT_EQ(intersect(a, b), (PixelSet{3, 5}));
}

TEST(PixelSet, SeparateFindsEightConnectedComponentsLargestFirst) {
  const GridShape shape{5, 10, false};
  // A diagonal pair (one component), a lone pixel, and a row of three.
  const PixelSet pixels = {
      static_cast<std::uint32_t>(shape.index(0, 0)), static_cast<std::uint32_t>(shape.index(1, 1)),
      static_cast<std::uint32_t>(shape.index(0, 5)), static_cast<std::uint32_t>(shape.index(4, 2)),
      static_cast<std::uint32_t>(shape.index(4, 3)), static_cast<std::uint32_t>(shape.index(4, 4))};
  PixelSet sorted = pixels;
  sort_pixels(sorted);
  const std::vector<PixelSet> parts = separate(shape, sorted);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].size(), 3u);
  EXPECT_EQ(parts[1], (PixelSet{0, 11}));
  EXPECT_EQ(parts[2], (PixelSet{5}));
}

TEST(PixelSet, SeparateJoinsAcrossTheSeamOnlyWhereTheGridWraps) {
  const PixelSet pixels = {20, 29};  // row 2, columns 0 and 9
  EXPECT_EQ(separate(GridShape{5, 10, true}, pixels).size(), 1u);
  EXPECT_EQ(separate(GridShape{5, 10, false}, pixels).size(), 2u);
}

TEST(PixelSet, MasksRoundTrip) {
  const GridShape shape{3, 4, false};
  const PixelSet pixels = {0, 5, 11};
  const std::vector<std::uint8_t> mask = to_mask(shape, pixels, 7);
  EXPECT_EQ(mask[5], 7);
  EXPECT_EQ(from_mask(mask), pixels);
}

}  // namespace
}  // namespace scanbench::segmentation

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "segmentation/constraints.hpp"
#include "segmentation/pixel_set.hpp"
#include "segmentation/proposals.hpp"
#include "segmentation/room_scene.hpp"

namespace scanbench::segmentation {
namespace {

using test::shared_room;

ProposalResult propose_room(std::span<const std::uint8_t> taken = {}) {
  const auto& room = shared_room();
  const SegmentationGrid grid = prepare_grid(room.scan, room.geometry, GridSettings{});
  const std::vector<std::uint8_t> open = open_pixels(grid, Constraints{}, taken);
  return propose_regions(grid, open, room.geometry.confidence, ProposalSettings{});
}

// The best IoU of any region with the usable pixels of `objects`.
double best_iou(const ProposalResult& proposals, std::initializer_list<std::uint8_t> objects) {
  const auto& room = shared_room();
  PixelSet truth;
  for (std::size_t i = 0; i < room.truth.size(); ++i) {
    const bool usable = acquisition::in_model(room.scan, room.geometry, i);
    if (usable && std::find(objects.begin(), objects.end(), room.truth[i]) != objects.end()) {
      truth.push_back(static_cast<std::uint32_t>(i));
    }
  }
  double best = 0.0;
  for (const PixelSet& region : proposals.regions) {
    const double common = static_cast<double>(intersect(region, truth).size());
    best = std::max(best, common / static_cast<double>(region.size() + truth.size() - common));
  }
  return best;
}

TEST(Proposals, EverySurfaceOfTheRoomIsOneRegion) {
  const ProposalResult proposals = propose_room();
  for (const std::uint8_t object :
       {test::kFloor, test::kWallMinusX, test::kWallPlusY, test::kWallMinusY, test::kWindow}) {
    EXPECT_GT(best_iou(proposals, {object}), 0.97) << int{object};
  }
  // The poster is flush with its wall: to the normals it is the wall. The
  // wall's reveals round the window, seen edge-on, are not.
  EXPECT_GT(best_iou(proposals, {test::kWallPlusX, test::kPoster}), 0.95);
}

TEST(Proposals, RegionsAreDisjointSortedAndLargeEnough) {
  const ProposalResult proposals = propose_room();
  ASSERT_FALSE(proposals.regions.empty());
  std::size_t total = 0;
  PixelSet all;
  for (const PixelSet& region : proposals.regions) {
    EXPECT_GE(region.size(), ProposalSettings{}.min_pixels);
    EXPECT_TRUE(std::is_sorted(region.begin(), region.end()));
    total += region.size();
    all = unite(all, region);
  }
  EXPECT_EQ(all.size(), total) << "a pixel in two regions";
  EXPECT_EQ(proposals.pixels, total);
}

TEST(Proposals, TakenPixelsAreInNoRegion) {
  const auto& room = shared_room();
  std::vector<std::uint8_t> taken(room.truth.size(), 0);
  for (std::size_t i = 0; i < taken.size(); ++i) taken[i] = room.truth[i] == test::kFloor;
  const ProposalResult proposals = propose_room(taken);
  for (const PixelSet& region : proposals.regions) {
    for (const std::uint32_t p : region) ASSERT_FALSE(taken[p]) << p;
  }
  EXPECT_GT(best_iou(proposals, {test::kWallPlusY}), 0.97);
}

}  // namespace
}  // namespace scanbench::segmentation

// registration::SampleShelf (core::SpillShelf of sample clouds) gives back
// every cloud as it was put, whether it stayed in memory or was read back
// from its file; a cloud handed out stays whole after the shelf lets it go,
// and a released one is gone; slots added later work as the first ones.
#include <gtest/gtest.h>

#include "core/spill_file.hpp"
#include "registration/sample_shelf.hpp"

namespace scanbench::registration {
namespace {

// A cloud of `n` samples whose values tell the scan and the sample.
SampleCloud cloud_of(std::size_t scan, std::size_t n) {
  SampleCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = static_cast<float>(scan * 1000 + i);
    cloud.points.emplace_back(v, v + 0.5f, -v);
    cloud.normals.emplace_back(0.0f, 0.0f, v > 0.0f ? 1.0f : -1.0f);
    cloud.pixels.push_back(static_cast<std::int64_t>(scan) << 33 | static_cast<std::int64_t>(i));
  }
  return cloud;
}

void expect_same(const SampleCloud& a, const SampleCloud& b) {
  EXPECT_EQ(a.points, b.points);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.pixels, b.pixels);
}

TEST(SampleShelf, GivesBackEveryCloudAsItWasPut) {
  SampleShelf shelf(6, 2);  // two in memory: the others come from the file
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_FALSE(shelf.has(k));
    shelf.put(k, cloud_of(k, k == 3 ? 0 : 100 + k));
    EXPECT_TRUE(shelf.has(k));
  }
  for (const std::size_t k : {0U, 5U, 1U, 3U, 0U, 4U, 2U}) {
    EXPECT_EQ(shelf.count(k), k == 3 ? 0U : 100 + k);
    expect_same(*shelf.get(k), cloud_of(k, shelf.count(k)));
  }
}

TEST(SampleShelf, AShelfThatKeepsNoneReadsEveryCloudBack) {
  SampleShelf shelf(2, 0);
  shelf.put(0, cloud_of(0, 20));
  shelf.put(1, cloud_of(1, 30));
  for (const std::size_t k : {1U, 0U, 1U}) expect_same(*shelf.get(k), cloud_of(k, shelf.count(k)));
}

TEST(SampleShelf, ACloudHandedOutOutlivesItsPlaceInMemory) {
  SampleShelf shelf(3, 1);
  shelf.put(0, cloud_of(0, 50));
  const std::shared_ptr<const SampleCloud> held = shelf.get(0);
  shelf.put(1, cloud_of(1, 50));
  shelf.put(2, cloud_of(2, 50));
  expect_same(*held, cloud_of(0, 50));
  expect_same(*shelf.get(0), cloud_of(0, 50));
}

TEST(SampleShelf, AReleasedCloudIsGoneAndTheOthersStay) {
  SampleShelf shelf(3, 1);
  for (std::size_t k = 0; k < 3; ++k) shelf.put(k, cloud_of(k, 40));
  const std::shared_ptr<const SampleCloud> held = shelf.get(1);
  shelf.release(1);
  shelf.release(1);  // nothing more to let go
  EXPECT_FALSE(shelf.has(1));
  expect_same(*held, cloud_of(1, 40));
  for (const std::size_t k : {2U, 0U, 2U}) expect_same(*shelf.get(k), cloud_of(k, 40));
  if (core::SpillFile().usable()) {
    EXPECT_EQ(shelf.bytes_in_memory(), 0U);  // the file took every cloud
  }
}

// Slots added after the shelf was made (as the patches of a registration's
// edges are) come after the first ones, and come back as they were put.
TEST(SampleShelf, AddedCloudsTakeNewSlotsAfterTheOthers) {
  SampleShelf shelf(2, 1);
  shelf.put(0, cloud_of(0, 30));
  EXPECT_EQ(shelf.add(cloud_of(2, 20)), 2U);
  EXPECT_EQ(shelf.add(cloud_of(3, 10)), 3U);
  EXPECT_EQ(shelf.size(), 4U);
  EXPECT_FALSE(shelf.has(1));
  shelf.release(2);
  EXPECT_FALSE(shelf.has(2));
  expect_same(*shelf.get(3), cloud_of(3, 10));
  expect_same(*shelf.get(0), cloud_of(0, 30));
  expect_same(*shelf.get(3), cloud_of(3, 10));
}

}  // namespace
}  // namespace scanbench::registration

// core::SpillShelf where its spill file cannot be made: every value stays
// in memory, is counted in bytes_in_memory() until released, and comes
// back as it was put. (The parked path: tests/registration/
// test_sample_shelf.cpp.)
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "core/spill_file.hpp"
#include "core/spill_shelf.hpp"
#include "support/test_support.hpp"

namespace scanbench::core {
namespace {

struct Values {
  std::vector<std::int64_t> keys;
  std::vector<float> weights;
  std::size_t size() const { return keys.size(); }
  auto vectors() { return std::tie(keys, weights); }
  auto vectors() const { return std::tie(keys, weights); }
};

Values values_of(std::size_t n) {
  Values v;
  for (std::size_t i = 0; i < n; ++i) {
    v.keys.push_back(static_cast<std::int64_t>(i) * 7);
    v.weights.push_back(0.5f * static_cast<float>(i));
  }
  return v;
}

using test::NoTemporaryFiles;

TEST(SpillShelf, WithoutASpillFileValuesStayInMemoryAndAreCounted) {
  const NoTemporaryFiles no_files;
  if (SpillFile().usable()) GTEST_SKIP() << "a file could be made in /proc here";
  SpillShelf<Values> shelf(3, 0);
  shelf.put(0, values_of(10));
  shelf.put(2, values_of(4));
  constexpr std::uint64_t kBytesPerValue = sizeof(std::int64_t) + sizeof(float);
  EXPECT_EQ(shelf.bytes_in_memory(), 14 * kBytesPerValue);
  EXPECT_FALSE(shelf.has(1));
  for (const std::size_t slot : {2U, 0U, 2U}) {
    const Values expected = values_of(shelf.count(slot));
    EXPECT_EQ(shelf.get(slot)->keys, expected.keys);
    EXPECT_EQ(shelf.get(slot)->weights, expected.weights);
  }
  shelf.release(0);
  EXPECT_FALSE(shelf.has(0));
  EXPECT_EQ(shelf.bytes_in_memory(), 4 * kBytesPerValue);
  shelf.release(2);
  EXPECT_EQ(shelf.bytes_in_memory(), 0U);
}

}  // namespace
}  // namespace scanbench::core

// core::SpillFile gives back what it was given, wherever it was put, and
// says when it cannot take more rather than losing it.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <vector>

#include "core/errors.hpp"
#include "core/spill_file.hpp"

namespace scanbench::core {
namespace {

TEST(SpillFile, GivesBackEachPutWhereverItWent) {
  SpillFile file;
  ASSERT_TRUE(file.usable());
  std::vector<std::uint8_t> first(3 << 20);
  std::iota(first.begin(), first.end(), std::uint8_t{7});
  const std::vector<float> second{1.5f, -2.0f, 3.25f};
  const std::optional<SpillFile::Extent> a = file.put(first.data(), first.size());
  const std::optional<SpillFile::Extent> b = file.put(second.data(), sizeof(float) * 3);
  const std::optional<SpillFile::Extent> empty = file.put(nullptr, 0);
  ASSERT_TRUE(a && b && empty);
  EXPECT_EQ(b->offset, first.size());
  EXPECT_EQ(file.size(), first.size() + sizeof(float) * 3);

  std::vector<float> second_back(3);
  file.get(*b, second_back.data());
  EXPECT_EQ(second_back, second);
  std::vector<std::uint8_t> first_back(first.size());
  file.get(*a, first_back.data());
  EXPECT_EQ(first_back, first);
  file.get(*empty, nullptr);

  // Giving the first one's space back leaves the second, and room for more.
  file.release(*a);
  std::fill(second_back.begin(), second_back.end(), 0.0f);
  file.get(*b, second_back.data());
  EXPECT_EQ(second_back, second);
  const std::optional<SpillFile::Extent> third = file.put(first.data(), 16);
  ASSERT_TRUE(third);
  EXPECT_EQ(third->offset, first.size() + sizeof(float) * 3);
}

TEST(SpillFile, VectorsComeBackWithTheirSizes) {
  SpillFile file;
  ASSERT_TRUE(file.usable());
  const std::vector<std::int64_t> pixels{5, 9, 1 << 30};
  const std::vector<float> values{0.25f, -7.0f};
  const std::vector<double> none;
  const std::optional<std::vector<SpillFile::Extent>> extents =
      file.put_vectors(pixels, values, none);
  ASSERT_TRUE(extents);
  ASSERT_EQ(extents->size(), 3U);
  std::vector<std::int64_t> pixels_back{1};
  std::vector<float> values_back;
  std::vector<double> none_back{2.0, 3.0};
  file.get_vectors(*extents, pixels_back, values_back, none_back);
  EXPECT_EQ(pixels_back, pixels);
  EXPECT_EQ(values_back, values);
  EXPECT_TRUE(none_back.empty());
}

TEST(SpillFile, AReadBeyondWhatWasPutIsARuntimeFailure) {
  SpillFile file;
  ASSERT_TRUE(file.usable());
  const std::uint32_t value = 42;
  ASSERT_TRUE(file.put(&value, sizeof value));
  std::vector<std::uint8_t> back(64);
  EXPECT_THROW(file.get({0, back.size()}, back.data()), RuntimeFailure);
}

}  // namespace
}  // namespace scanbench::core

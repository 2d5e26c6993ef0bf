#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "core/radix_sort.hpp"

namespace scanbench::core {
namespace {

using Keyed = std::pair<std::uint64_t, std::uint32_t>;  // key, original position

// Items with keys of `bits` bits (many repeated), numbered in order.
std::vector<Keyed> random_items(std::size_t n, int bits, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  const std::uint64_t mask = bits == 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
  std::vector<Keyed> items(n);
  for (std::size_t i = 0; i < n; ++i) {
    // A quarter of the keys come from a pool of 16: runs of equal keys.
    const std::uint64_t key = i % 4 == 0 ? (random() % 16) * (mask / 16) : random() & mask;
    items[i] = {key, static_cast<std::uint32_t>(i)};
  }
  return items;
}

TEST(RadixSort, SortsStablyByKeyAsAComparisonSortDoes) {
  for (const int bits : {0, 5, 11, 22, 37, 51, 64}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{200}, std::size_t{255},
                                std::size_t{256}, std::size_t{5000}, std::size_t{100000}}) {
      SCOPED_TRACE(testing::Message() << bits << " bits, " << n << " items");
      std::vector<Keyed> items = random_items(n, bits, 7u * n + static_cast<unsigned>(bits));
      std::vector<Keyed> expected = items;
      std::stable_sort(expected.begin(), expected.end(),
                       [](const Keyed& a, const Keyed& b) { return a.first < b.first; });
      std::vector<Keyed> scratch;
      radix_sort(items, scratch, bits, [](const Keyed& k) { return k.first; });
      // Equal keys keep their order: the positions break the ties as a
      // stable sort leaves them.
      EXPECT_EQ(items, expected);
    }
  }
}

TEST(RadixSort, SkipsADigitEveryKeyShares) {
  // Keys that differ only in their lowest and highest digits.
  std::vector<std::uint64_t> keys;
  for (std::uint64_t k = 0; k < 1000; ++k) keys.push_back(((999 - k) % 7) | (k % 3) << 40);
  std::vector<std::uint64_t> expected = keys;
  std::sort(expected.begin(), expected.end());
  std::vector<std::uint64_t> scratch;
  std::size_t keys_read = 0;
  radix_sort(keys, scratch, 48, [&](std::uint64_t k) {
    ++keys_read;
    return k;
  });
  EXPECT_EQ(keys, expected);
  // Five digits of 11 bits cover 48 bits; each is counted (a read a key),
  // and only the two that differ are distributed (another read a key).
  EXPECT_EQ(keys_read, (5 + 2) * keys.size());
}

}  // namespace
}  // namespace scanbench::core

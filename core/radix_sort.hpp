// A least-significant-digit radix sort: linear in the number of items, for
// large arrays sorted by an integer key (pixel indices, Morton codes).
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace scanbench::core {

// Sorts `items` stably by key(item), an unsigned integer below 2^bits
// (asserted), in passes of 11 bits, skipping a pass whose digit every item
// shares. `scratch` is working room (its contents are lost). Below 256
// items, a comparison sort.
template <typename T, typename Key>
void radix_sort(std::vector<T>& items, std::vector<T>& scratch, int bits, Key&& key) {
  assert(bits >= 0 && bits <= 64 && "a key of 64 bits at most");
  const auto by_key = [&](const T& a, const T& b) { return key(a) < key(b); };
  if (items.size() < 256) {
    std::stable_sort(items.begin(), items.end(), by_key);
    return;
  }
  constexpr int kDigitBits = 11;
  constexpr std::uint64_t kDigits = std::uint64_t{1} << kDigitBits;
  scratch.resize(items.size());
  std::array<std::size_t, kDigits> start{};
  for (int shift = 0; shift < bits; shift += kDigitBits) {
    start.fill(0);
    for (const T& item : items) {
      const auto k = static_cast<std::uint64_t>(key(item));
      assert((bits == 64 || k >> bits == 0) && "keys below 2^bits");
      ++start[(k >> shift) & (kDigits - 1)];
    }
    if (std::find(start.begin(), start.end(), items.size()) != start.end()) continue;
    std::size_t below = 0;
    for (std::size_t& s : start) below += std::exchange(s, below);
    for (const T& item : items)
      scratch[start[(static_cast<std::uint64_t>(key(item)) >> shift) & (kDigits - 1)]++] = item;
    items.swap(scratch);
  }
}

}  // namespace scanbench::core

#include "segmentation/pixel_set.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <iterator>

#include "core/radix_sort.hpp"

namespace scanbench::segmentation {

void sort_pixels(std::vector<std::uint32_t>& pixels) {
  std::vector<std::uint32_t> scratch;
  core::radix_sort(pixels, scratch, 32, [](std::uint32_t v) { return v; });
}

PixelSet unite(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
  PixelSet out;
  out.reserve(a.size() + b.size());
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

PixelSet subtract(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
  PixelSet out;
  out.reserve(a.size());
  std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

PixelSet intersect(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b) {
  PixelSet out;
  std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

std::vector<PixelSet> separate(const GridShape& shape, std::span<const std::uint32_t> pixels) {
  // 1 = in the set and not yet in a component.
  std::vector<std::uint8_t> pending = to_mask(shape, pixels);
  std::vector<PixelSet> components;
  std::vector<std::uint32_t> stack;
  for (const std::uint32_t start : pixels) {
    if (!pending[start]) continue;
    PixelSet component;
    pending[start] = 0;
    stack.push_back(start);
    while (!stack.empty()) {
      const std::uint32_t p = stack.back();
      stack.pop_back();
      component.push_back(p);
      const int row = static_cast<int>(p / static_cast<std::uint32_t>(shape.columns));
      const int col = static_cast<int>(p % static_cast<std::uint32_t>(shape.columns));
      shape.for_each_neighbour(row, col, [&](int r, int c) {
        const auto q = static_cast<std::uint32_t>(shape.index(r, c));
        if (!pending[q]) return;
        pending[q] = 0;
        stack.push_back(q);
      });
    }
    sort_pixels(component);
    components.push_back(std::move(component));
  }
  // Components were found in the order of their smallest pixel.
  std::stable_sort(components.begin(), components.end(),
                   [](const PixelSet& a, const PixelSet& b) { return a.size() > b.size(); });
  return components;
}

std::vector<std::uint8_t> to_mask(const GridShape& shape, std::span<const std::uint32_t> pixels,
                                  std::uint8_t value) {
  std::vector<std::uint8_t> mask(shape.pixel_count(), 0);
  for (const std::uint32_t p : pixels) {
    assert(p < mask.size() && "pixel outside the grid");
    mask[p] = value;
  }
  return mask;
}

PixelSet from_mask(std::span<const std::uint8_t> mask) {
  PixelSet out;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) out.push_back(static_cast<std::uint32_t>(i));
  }
  return out;
}

}  // namespace scanbench::segmentation

// Sets of pixels of one scan grid: what a region, a selection and an
// object's membership in one scan are. A set is its row-major indices in
// ascending order, so set operations cost time in proportion to the sets,
// not to the scan.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "segmentation/segmentation_grid.hpp"

namespace scanbench::segmentation {

using PixelSet = std::vector<std::uint32_t>;  // ascending, no repeats

// Sorts row-major indices ascending (radix sort: linear in their number).
void sort_pixels(std::vector<std::uint32_t>& pixels);

PixelSet unite(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b);
PixelSet subtract(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b);
PixelSet intersect(std::span<const std::uint32_t> a, std::span<const std::uint32_t> b);

// The 8-connected components of `pixels` on `shape` (wrapping like it),
// largest first; components of equal size in the order of their smallest
// pixel.
std::vector<PixelSet> separate(const GridShape& shape, std::span<const std::uint32_t> pixels);

// One byte per pixel of `shape`: `value` on the set's pixels, 0 elsewhere.
std::vector<std::uint8_t> to_mask(const GridShape& shape, std::span<const std::uint32_t> pixels,
                                  std::uint8_t value = 1);
// The pixels where `mask` is non-zero.
PixelSet from_mask(std::span<const std::uint8_t> mask);

}  // namespace scanbench::segmentation

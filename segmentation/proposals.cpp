#include "segmentation/proposals.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>

namespace scanbench::segmentation {

namespace {

// Pixel indices where open, by decreasing rank (a stable counting sort on
// the rank quantised to 1/1024 of its finite range: seeds need an order,
// not an exact one), ties in row-major order; ranks that are not finite
// come last.
std::vector<std::uint32_t> seed_order(std::span<const std::uint8_t> open,
                                      std::span<const float> rank) {
  float low = 0.0f, high = 0.0f;
  bool any = false;
  for (std::size_t i = 0; i < rank.size(); ++i) {
    if (!open[i] || !std::isfinite(rank[i])) continue;
    low = any ? std::min(low, rank[i]) : rank[i];
    high = any ? std::max(high, rank[i]) : rank[i];
    any = true;
  }
  constexpr int kBuckets = 1024;
  const float scale = high > low ? (kBuckets - 1) / (high - low) : 0.0f;
  const auto bucket = [&](std::size_t i) {
    if (!std::isfinite(rank[i])) return kBuckets;  // a bucket after every finite rank
    return kBuckets - 1 - static_cast<int>((rank[i] - low) * scale);
  };
  std::vector<std::size_t> start(kBuckets + 2, 0);
  for (std::size_t i = 0; i < rank.size(); ++i) {
    if (open[i]) ++start[static_cast<std::size_t>(bucket(i)) + 1];
  }
  for (int b = 0; b <= kBuckets; ++b) start[b + 1] += start[b];
  std::vector<std::uint32_t> order(start[kBuckets + 1]);
  for (std::size_t i = 0; i < rank.size(); ++i) {
    if (open[i])
      order[start[static_cast<std::size_t>(bucket(i))]++] = static_cast<std::uint32_t>(i);
  }
  return order;
}

}  // namespace

ProposalResult propose_regions(const SegmentationGrid& grid, std::span<const std::uint8_t> open,
                               std::span<const float> seed_rank, const ProposalSettings& settings) {
  const std::size_t n = grid.shape.pixel_count();
  assert(open.size() == n && seed_rank.size() == n && "arrays of another grid");
  const auto start = std::chrono::steady_clock::now();
  ProposalResult result;
  std::vector<std::uint8_t> free(open.begin(), open.end());  // open and in no region
  std::vector<std::uint8_t> tried(n, 0);                     // no longer a seed
  RegionGrower grower(grid);
  for (const std::uint32_t seed : seed_order(open, seed_rank)) {
    if (tried[seed] || !free[seed]) continue;
    GrowResult grown = grower.grow(seed, settings.grow, free);
    for (const std::uint32_t p : grown.pixels) tried[p] = 1;
    if (grown.pixels.size() < std::max<std::size_t>(1, settings.min_pixels)) continue;
    for (const std::uint32_t p : grown.pixels) free[p] = 0;
    result.pixels += grown.pixels.size();
    result.regions.push_back(std::move(grown.pixels));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace scanbench::segmentation

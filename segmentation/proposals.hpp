// Automatic proposals for a whole scan (seed 004 §4.1, the step before the
// user's clicks): smooth-surface region growing from the best-fitted pixels
// first, so that the large planes of buildings and the ground come out as
// regions the user can accept, merge or reject instead of clicking them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "segmentation/pixel_set.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::segmentation {

struct ProposalSettings {
  // How each region grows (the normal channel by default: smooth surfaces).
  GrowSettings grow = default_grow_settings(Channel::kNormal);
  // Regions with fewer pixels are not proposed; their pixels stay free and
  // may join a later region.
  std::size_t min_pixels = 200;
};

struct ProposalResult {
  std::vector<PixelSet> regions;  // in the order they were found: best seeds first
  std::size_t pixels = 0;         // pixels in some region
  double seconds = 0.0;
};

// Proposes regions on `grid` among the pixels where open[i] != 0 (one byte
// per pixel, asserted). Seeds are taken in order of decreasing `seed_rank`
// (one value per pixel, asserted; the geometry's confidence, say), ranks
// within 1/1024 of their finite range counting as equal and ties in
// row-major order; pixels whose rank is not finite are seeds last. A pixel
// already in a region, or in a region too small to propose, is no seed.
// Each pixel belongs to at most one region.
ProposalResult propose_regions(const SegmentationGrid& grid, std::span<const std::uint8_t> open,
                               std::span<const float> seed_rank, const ProposalSettings& settings);

}  // namespace scanbench::segmentation

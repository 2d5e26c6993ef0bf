// Which scans of a project can share a surface, decided from the summaries
// the project keeps (world bounds at the current poses) without loading a
// scan: what lets a streamed stage compare each scan only with its
// neighbours instead of with every other scan. Internal to modeling/.
#pragma once

#include <span>
#include <vector>

#include "modeling/store/project.hpp"

namespace scanbench::modeling {

// Two scans whose world bounds are farther apart than this [m] share no
// surface: a point of one lies within the same-surface tolerance (range
// noise plus a footprint) of the other's points only when it is much closer.
inline constexpr double kSharedSurfaceMarginM = 5.0;

// A pair of positions in the scan list, first < second.
struct ScanPair {
  int first = 0;
  int second = 0;
  friend bool operator==(const ScanPair&, const ScanPair&) = default;
};

// Every pair of `scans` whose world bounds, grown by `margin_m`, intersect,
// ordered by second, then first. A scan without bounds (no valid point)
// pairs with none. O(N log N + pairs): a sweep along x.
std::vector<ScanPair> overlapping_pairs(std::span<const store::StoredScanSummary> scans,
                                        double margin_m = kSharedSurfaceMarginM);

}  // namespace scanbench::modeling

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

// Whether `scan`'s world bounds, grown by `margin_m`, meet `box`: whether
// the scan may hold points of a surface within `box`. False for a scan
// without bounds.
bool bounds_reach(const store::StoredScanSummary& scan, const Eigen::AlignedBox3d& box,
                  double margin_m = kSharedSurfaceMarginM);

// A pair of positions in the scan list, first < second.
struct ScanPair {
  int first = 0;
  int second = 0;
  friend bool operator==(const ScanPair&, const ScanPair&) = default;
};

// Every pair of `scans` whose world bounds, grown by `margin_m`, intersect,
// ordered by second, then first. A scan without bounds (no valid point)
// pairs with none. A sweep along x: O(N log N + pairs) where the scans
// spread along x, up to N² box tests where they line up along y or z.
std::vector<ScanPair> overlapping_pairs(std::span<const store::StoredScanSummary> scans,
                                        double margin_m = kSharedSurfaceMarginM);

// The scans a pass over `pairs` (ordered as overlapping_pairs orders them)
// takes, by position: each pair's second scan, then the first scan of each
// of its pairs. With `every_scan` also the scans that are second in no
// pair, in their place, so that the pass visits each of the `scan_count`
// scans.
std::vector<int> pair_pass_order(std::span<const ScanPair> pairs, int scan_count, bool every_scan);

}  // namespace scanbench::modeling

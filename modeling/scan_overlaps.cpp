#include "modeling/scan_overlaps.hpp"

#include <algorithm>

namespace scanbench::modeling {
namespace {

// `box` grown by `margin_m` on every side.
Eigen::AlignedBox3d grown_by(const Eigen::AlignedBox3d& box, double margin_m) {
  return {box.min().array() - margin_m, box.max().array() + margin_m};
}

}  // namespace

std::vector<ScanPair> overlapping_pairs(std::span<const store::StoredScanSummary> scans,
                                        double margin_m) {
  std::vector<int> by_x;  // positions of the scans with bounds, by their lowest x
  for (int k = 0; k < static_cast<int>(scans.size()); ++k) {
    if (scans[static_cast<std::size_t>(k)].summary.bbox_world) by_x.push_back(k);
  }
  const auto box = [&scans](int k) -> const Eigen::AlignedBox3d& {
    return *scans[static_cast<std::size_t>(k)].summary.bbox_world;
  };
  std::sort(by_x.begin(), by_x.end(),
            [&box](int a, int b) { return box(a).min().x() < box(b).min().x(); });
  std::vector<ScanPair> pairs;
  for (std::size_t i = 0; i < by_x.size(); ++i) {
    const Eigen::AlignedBox3d grown = grown_by(box(by_x[i]), margin_m);
    for (std::size_t j = i + 1; j < by_x.size(); ++j) {
      const Eigen::AlignedBox3d& other = box(by_x[j]);
      if (other.min().x() > grown.max().x()) break;
      if (grown.intersects(other)) {
        pairs.push_back({std::min(by_x[i], by_x[j]), std::max(by_x[i], by_x[j])});
      }
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const ScanPair& a, const ScanPair& b) {
    return a.second != b.second ? a.second < b.second : a.first < b.first;
  });
  return pairs;
}

std::vector<int> pair_pass_order(std::span<const ScanPair> pairs, int scan_count, bool every_scan) {
  std::vector<int> order;
  auto pair = pairs.begin();
  for (int second = 0; second < scan_count; ++second) {
    const bool paired = pair != pairs.end() && pair->second == second;
    if (paired || every_scan) order.push_back(second);
    for (; pair != pairs.end() && pair->second == second; ++pair) order.push_back(pair->first);
  }
  return order;
}

bool bounds_reach(const store::StoredScanSummary& scan, const Eigen::AlignedBox3d& box,
                  double margin_m) {
  if (!scan.summary.bbox_world || box.isEmpty()) return false;
  return grown_by(*scan.summary.bbox_world, margin_m).intersects(box);
}

}  // namespace scanbench::modeling

#include "registration/overlap_screening.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "registration/icp.hpp"

namespace scanbench::registration {
namespace {

// The bounds of a sample cloud in its scan's frame; empty for no sample.
Eigen::AlignedBox3d bounds_of(const SampleCloud& cloud) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& p : cloud.points) box.extend(p.cast<double>());
  return box;
}

// Whether `a` (a box in its own frame, moved by T_b_a) comes within
// margin_m of `b`. Conservative: the moved box's axis-aligned bounds.
bool boxes_meet(const Eigen::AlignedBox3d& a, const Eigen::Isometry3d& T_b_a,
                const Eigen::AlignedBox3d& b, double margin_m) {
  if (a.isEmpty() || b.isEmpty()) return false;
  Eigen::AlignedBox3d moved;
  for (int corner = 0; corner < 8; ++corner)
    moved.extend(T_b_a * a.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
  const Eigen::AlignedBox3d grown(b.min().array() - margin_m, b.max().array() + margin_m);
  return grown.intersects(moved);
}

// A source sample counts as overlapping only within the gate of the
// overlap test (IcpSettings::min_gate_m, measure_alignment), so pairs whose
// samples' bounds stay farther apart than that cannot overlap; one metre
// more covers the samples' voxels (SampleSettings::voxel_m) and rounding.
double pair_reach_m(const RegistrationSettings& settings) {
  return settings.icp.min_gate_m + settings.icp_sample.voxel_m + 1.0;
}

// Cells of edge cell_m in the first scan's frame: integer indices per
// axis, packed 21 bits each (±1 048 576 cells, over a thousand kilometres
// at the reach), clamped at the edges.
using CellIndex = Eigen::Array<std::int64_t, 3, 1>;

CellIndex cell_of(const Eigen::Vector3d& p, double cell_m) {
  constexpr double kLimit = (1 << 20) - 2;  // a neighbour of an edge cell still fits
  CellIndex cell;
  for (int axis = 0; axis < 3; ++axis)
    cell[axis] =
        static_cast<std::int64_t>(std::clamp(std::floor(p[axis] / cell_m), -kLimit, kLimit));
  return cell;
}

std::uint64_t cell_key(const CellIndex& cell) {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis)
    key = (key << 21) | static_cast<std::uint64_t>((cell[axis] + (1 << 20)) & ((1 << 21) - 1));
  return key;
}

// The cells that a sample cloud at pose T_first_cloud occupies, sorted.
std::vector<std::uint64_t> occupied_cells(const SampleCloud& cloud,
                                          const Eigen::Isometry3d& T_first_cloud, double cell_m) {
  std::vector<std::uint64_t> cells;
  cells.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points)
    cells.push_back(cell_key(cell_of(T_first_cloud * p.cast<double>(), cell_m)));
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

// The share of `cloud`'s points (at T_first_cloud) whose cell or one of its
// 26 neighbours is among `cells`: an upper bound of the share with a
// correspondence closer than cell_m, computed from the samples alone.
double reachable_share(const SampleCloud& cloud, const Eigen::Isometry3d& T_first_cloud,
                       const std::vector<std::uint64_t>& cells, double cell_m) {
  if (cloud.points.empty() || cells.empty()) return 0.0;
  std::size_t reachable = 0;
  for (const Eigen::Vector3f& point : cloud.points) {
    const CellIndex cell = cell_of(T_first_cloud * point.cast<double>(), cell_m);
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          found = std::binary_search(cells.begin(), cells.end(),
                                     cell_key(cell + CellIndex(dx, dy, dz)));
        }
      }
    }
    reachable += found;
  }
  return static_cast<double>(reachable) / static_cast<double>(cloud.size());
}

}  // namespace

// The pairs of registered scans that overlap at the given poses. Of the
// earlier scans whose samples' bounds meet a scan's, and that enough of its
// thinned samples come within a cell (the reach) of, the ones reached most
// (max_overlap_tests_per_scan) are measured on the target scan, target by
// target: the pair tests grow with the scans, not with the scans in sight.
std::vector<ScanEdge> overlapping_edges(ScanStream& scans, SampleShelf& samples,
                                        EdgePatches& patches,
                                        const std::vector<Eigen::Isometry3d>& T_first_scan,
                                        const std::vector<bool>& registered,
                                        const RegistrationSettings& settings,
                                        std::size_t& pair_tests) {
  const int n = static_cast<int>(scans.size());
  const double reach = pair_reach_m(settings);
  std::vector<Eigen::AlignedBox3d> bounds;
  std::vector<std::vector<std::uint64_t>> cells;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const std::shared_ptr<const SampleCloud> cloud = samples.get(k);
    bounds.push_back(bounds_of(*cloud));
    cells.push_back(occupied_cells(*cloud, T_first_scan[k], reach));
  }
  // A decision on a share: a thinned sample will do.
  SampleShelf estimates(samples.size(), kSamplesKept);
  std::vector<ScanEdge> candidates;  // in (source, target) order
  for (int a = 1; a < n; ++a) {
    const auto ua = static_cast<std::size_t>(a);
    std::vector<std::pair<double, int>> reached;  // (share, target)
    for (int b = 0; b < a; ++b) {
      const auto ub = static_cast<std::size_t>(b);
      if (!registered[ua] || !registered[ub]) continue;
      if (!boxes_meet(bounds[ua], T_first_scan[ub].inverse() * T_first_scan[ua], bounds[ub],
                      reach)) {
        continue;
      }
      if (!estimates.has(ua)) estimates.put(ua, thin(*samples.get(ua), settings.estimate_samples));
      const double share = reachable_share(*estimates.get(ua), T_first_scan[ua], cells[ub], reach);
      if (share >= settings.min_global_overlap) reached.emplace_back(share, b);
    }
    // The most reached first (ties: the earlier scan), then in scan order.
    std::stable_sort(reached.begin(), reached.end(),
                     [](const auto& x, const auto& y) { return x.first > y.first; });
    if (reached.size() > settings.max_overlap_tests_per_scan)
      reached.resize(settings.max_overlap_tests_per_scan);
    std::vector<int> targets;
    for (const auto& [share, b] : reached) targets.push_back(b);
    std::sort(targets.begin(), targets.end());
    for (const int b : targets) candidates.push_back({a, b});
  }
  std::vector<bool> overlapping(candidates.size(), false);
  for_each_target(scans, candidates, [&](const PreparedScan& target, std::size_t e) {
    const auto a = static_cast<std::size_t>(candidates[e].source);
    const auto b = static_cast<std::size_t>(candidates[e].target);
    const Eigen::Isometry3d T_target_source = T_first_scan[b].inverse() * T_first_scan[a];
    const AlignmentQuality quality =
        measure_alignment(*estimates.get(a), target, T_target_source, settings.icp);
    ++pair_tests;
    overlapping[e] = quality.overlap >= settings.min_global_overlap;
    if (overlapping[e]) patches.make(candidates[e], *samples.get(a), target, T_target_source);
  });
  std::vector<ScanEdge> edges;
  for (std::size_t e = 0; e < candidates.size(); ++e) {
    if (overlapping[e]) edges.push_back(candidates[e]);
  }
  return edges;
}

void report_edges(ScanStream& scans, SampleShelf& samples, EdgePatches& patches,
                  const std::vector<Eigen::Isometry3d>& T_first_scan,
                  const std::vector<ScanEdge>& edges, const RegistrationSettings& settings,
                  RegistrationResult& result) {
  std::vector<AlignmentQuality> qualities(edges.size());
  const auto T_target_source = [&](std::size_t e) {
    return Eigen::Isometry3d(T_first_scan[static_cast<std::size_t>(edges[e].target)].inverse() *
                             T_first_scan[static_cast<std::size_t>(edges[e].source)]);
  };
  const auto source = [&](std::size_t e) {
    return samples.get(static_cast<std::size_t>(edges[e].source));
  };
  patches.visit(
      scans, edges,
      [&](const PatchedTarget& target, std::size_t e) {
        const std::optional<AlignmentQuality> quality =
            measure_alignment(*source(e), target, T_target_source(e), settings.icp);
        if (quality) qualities[e] = *quality;
        return quality.has_value();
      },
      [&](const PreparedScan& target, std::size_t e) {
        qualities[e] = measure_alignment(*source(e), target, T_target_source(e), settings.icp);
      });
  double sum_squared = 0.0;
  std::size_t sample_count = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const AlignmentQuality& quality = qualities[e];
    result.edges.push_back({edges[e].source, edges[e].target, quality});
    sum_squared += quality.rms_m * quality.rms_m * static_cast<double>(quality.correspondences);
    result.correspondences += quality.correspondences;
    sample_count += samples.count(static_cast<std::size_t>(edges[e].source));
  }
  if (result.correspondences > 0) result.rms_m = std::sqrt(sum_squared / result.correspondences);
  if (sample_count > 0) result.overlap = static_cast<double>(result.correspondences) / sample_count;
}

}  // namespace scanbench::registration

// `scanbench bench merge` (issue #5). The campus campaign is merged at its
// true poses (registration error is bench "registration"'s business), then:
//
// - redundant_removed_share: of the in-model points whose surface another
//   scan sampled more finely by the truth (same object under that scan's
//   beam at the same true range, and a true sample area smaller by more
//   than the tie tolerance), the share the keep masks drop;
// - coverage_before / coverage_after: of a truth sampling of every visible
//   surface (every second row and column of every scan's noise-free points),
//   the share with an in-model (before) or kept (after) point within
//   2 × the sample's footprint. Points are compared at their noise-free
//   positions, so coverage measures which samples are kept, not range noise;
// - points_per_second: in-model points decided per second by
//   merge_by_sampling_rate, on all cores (preparing the scans, shared with
//   registration, is reported apart).
#include "bench/bench_merge.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <vector>

#include "bench/simulated_site.hpp"
#include "core/parallel.hpp"
#include "registration/merge.hpp"

namespace scanbench::bench {
namespace {

using registration::PreparedScan;

// Noise-free point of pixel i in its scan frame [m].
Eigen::Vector3f truth_point(const SimulatedSite& site, std::size_t s, std::size_t i) {
  const acquisition::Scan& scan = site.scans[s];
  const int row = static_cast<int>(i / static_cast<std::size_t>(scan.columns));
  const int col = static_cast<int>(i % static_cast<std::size_t>(scan.columns));
  return site.truth[s].range_m[i] * acquisition::direction(scan, row, col);
}

// True surface area per sample: r² · Ω / |cos incidence| (as PreparedScan).
float truth_area(const SimulatedSite& site, const PreparedScan& prepared, std::size_t s,
                 std::size_t i) {
  const acquisition::Scan& scan = site.scans[s];
  const float range = site.truth[s].range_m[i];
  const float measured = scan.range_m[i];
  // The prepared area with the true range and normal in place of the estimates.
  const Eigen::Vector3f d = truth_point(site, s, i).normalized();
  const float cos_true = std::max(std::abs(site.truth[s].normal_scan[i].dot(d)), 0.05f);
  const Eigen::Vector3f n = site.geometry[s].normal[i];
  const float cos_est = prepared.usable[i] ? std::max(std::abs(n.dot(d)), 0.05f) : 1.0f;
  const float omega = prepared.sample_area_m2[i] * cos_est / (measured * measured);
  return range * range * omega / cos_true;
}

struct Context {
  const SimulatedSite& site;
  std::span<const PreparedScan> prepared;
  std::vector<Eigen::Isometry3f> T_world_scan;
  double tie_tolerance;
};

bool truth_redundant(const Context& c, std::size_t s, std::size_t i) {
  const Eigen::Vector3f world = c.T_world_scan[s] * truth_point(c.site, s, i);
  const float area = truth_area(c.site, c.prepared[s], s, i);
  for (std::size_t o = 0; o < c.prepared.size(); ++o) {
    if (o == s) continue;
    const Eigen::Vector3f p = c.T_world_scan[o].inverse() * world;
    const std::int64_t pixel = registration::associate(c.prepared[o], p);
    if (pixel < 0) continue;
    const auto k = static_cast<std::size_t>(pixel);
    if (c.site.truth[o].object_id[k] != c.site.truth[s].object_id[i]) continue;
    if (std::abs(c.site.truth[o].range_m[k] - p.norm()) >
        0.05f + 2.0f * c.site.geometry[o].footprint_m[k]) {
      continue;
    }
    if (truth_area(c.site, c.prepared[o], o, k) < area / (1.0 + c.tie_tolerance)) return true;
  }
  return false;
}

// A kept point of some scan within 2 × footprint of truth sample i of scan s:
// searched in the 3 × 3 pixels around the sample's projection into each scan.
bool covered(const Context& c, const std::vector<std::vector<std::uint8_t>>& keep, std::size_t s,
             std::size_t i) {
  const Eigen::Vector3f world = c.T_world_scan[s] * truth_point(c.site, s, i);
  const float radius = 2.0f * c.site.geometry[s].footprint_m[i];
  for (std::size_t o = 0; o < c.prepared.size(); ++o) {
    const Eigen::Vector3f p = c.T_world_scan[o].inverse() * world;
    const std::int64_t pixel = registration::associate(c.prepared[o], p);
    if (pixel < 0) continue;
    const int columns = c.site.scans[o].columns;
    const int row = static_cast<int>(pixel / columns);
    const int col = static_cast<int>(pixel % columns);
    for (int r = std::max(0, row - 1); r <= std::min(c.site.scans[o].rows - 1, row + 1); ++r) {
      for (int q = std::max(0, col - 1); q <= std::min(columns - 1, col + 1); ++q) {
        const std::size_t k = c.site.scans[o].index(r, q);
        if (keep[o][k] && (truth_point(c.site, o, k) - p).norm() <= radius) return true;
      }
    }
  }
  return false;
}

struct Tally {
  std::atomic<std::size_t> redundant{0}, removed{0}, samples{0}, before{0}, after{0};
};

void tally_row(const Context& c, const std::vector<std::vector<std::uint8_t>>& in_model,
               const std::vector<std::vector<std::uint8_t>>& kept, std::size_t s, int row,
               Tally& t) {
  const acquisition::Scan& scan = c.site.scans[s];
  std::size_t redundant = 0, removed = 0, samples = 0, before = 0, after = 0;
  for (int col = 0; col < scan.columns; ++col) {
    const std::size_t i = scan.index(row, col);
    if (c.prepared[s].in_model[i] && !c.site.truth[s].mixed[i] && truth_redundant(c, s, i)) {
      ++redundant;
      removed += kept[s][i] == 0;
    }
    const bool sample = row % 2 == 0 && col % 2 == 0 && c.site.truth[s].object_id[i] != 0 &&
                        !c.site.truth[s].mixed[i] && c.site.geometry[s].footprint_m[i] > 0.0f;
    if (!sample) continue;
    ++samples;
    before += covered(c, in_model, s, i);
    after += covered(c, kept, s, i);
  }
  t.redundant += redundant;
  t.removed += removed;
  t.samples += samples;
  t.before += before;
  t.after += after;
}

double share(std::size_t part, std::size_t whole) {
  return whole > 0 ? static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

}  // namespace

nlohmann::json run_merge_bench(const BenchOptions& options) {
  acquisition::sim::ScannerModel model;
  if (options.smoke) {
    model.columns = 900;
    model.rows = 225;
  }
  const int scan_count = options.smoke ? 2 : 4;
  const SimulatedSite site = simulate_site("campus", model, scan_count);
  const auto prepare_start = std::chrono::steady_clock::now();
  std::vector<PreparedScan> prepared;
  for (std::size_t k = 0; k < site.scans.size(); ++k) {
    prepared.push_back(registration::prepare_scan(site.scans[k], site.geometry[k], 0));
  }
  const double prepare_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - prepare_start).count();
  const registration::MergeSettings settings;
  registration::MergeResult merged;
  for (int run = 0; run < (options.smoke ? 1 : 3); ++run) {  // best of runs
    registration::MergeResult r =
        registration::merge_by_sampling_rate(prepared, site.true_poses, settings);
    if (run == 0 || r.seconds < merged.seconds) merged = std::move(r);
  }

  Context context{site, prepared, {}, settings.tie_tolerance};
  std::vector<std::vector<std::uint8_t>> in_model, kept;
  for (std::size_t k = 0; k < site.scans.size(); ++k) {
    context.T_world_scan.push_back(site.true_poses[k].cast<float>());
    in_model.push_back(prepared[k].in_model);
    kept.push_back(merged.scans[k].keep);
  }
  Tally tally;
  for (std::size_t s = 0; s < site.scans.size(); ++s) {
    core::parallel_for_index(site.scans[s].rows, 0,
                             [&](int row) { tally_row(context, in_model, kept, s, row, tally); });
  }
  std::size_t kept_points = 0;
  for (const auto& scan : merged.scans) kept_points += scan.kept;
  nlohmann::json ours = {
      {"redundant_removed_share", share(tally.removed, tally.redundant)},
      {"coverage_before", share(tally.before, tally.samples)},
      {"coverage_after", share(tally.after, tally.samples)},
      {"points_per_second", merged.seconds > 0.0 ? merged.points / merged.seconds : 0.0},
      {"points", merged.points},
      {"kept_points", kept_points},
      {"truth_redundant_points", tally.redundant.load()},
      {"seconds", merged.seconds},
      {"prepare_seconds", prepare_seconds}};
  return {{"suite", "merge"},         {"site", "campus"},   {"scans", scan_count},
          {"columns", model.columns}, {"rows", model.rows}, {"ours", ours}};
}

}  // namespace scanbench::bench

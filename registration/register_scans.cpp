#include "registration/register_scans.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <optional>

#include "acquisition/timing.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {
namespace {

using Clock = std::chrono::steady_clock;

struct Candidate {
  std::string start;
  Eigen::Isometry3d T_target_source;
};

// Consistent with the target's free space beats not; then converged beats
// not converged; then more overlap; then a smaller RMS.
bool better(const IcpResult& a, const IcpResult& b, double max_violation) {
  const bool a_free = a.free_space_violation <= max_violation;
  const bool b_free = b.free_space_violation <= max_violation;
  if (a_free != b_free) return a_free;
  if (a.converged != b.converged) return a.converged;
  if (a.overlap != b.overlap) return a.overlap > b.overlap;
  return a.rms_m < b.rms_m;
}

const PickedPairs* picks_for(const RegistrationSettings& settings, int source) {
  for (const PickedPairs& picks : settings.picks) {
    if (picks.source == source) return &picks;
  }
  return nullptr;
}

// The coarse stage of one pair: its report, and the starts ICP tries.
std::vector<Candidate> coarse_stage(int source, const Eigen::Isometry3d& initial,
                                    const std::vector<FeatureCloud>& features,
                                    const RegistrationSettings& settings, int target,
                                    CoarseReport& report) {
  switch (settings.coarse) {
    case CoarseMethod::kNone:
      report.method = "none";
      report.success = true;
      return {{"initial", initial}};
    case CoarseMethod::kPointPairs: {
      report.method = "point_pairs";
      const PickedPairs* picks = picks_for(settings, source);
      assert(picks != nullptr && "every scan after the first needs picked pairs");
      const RigidFitResult fit = fit_rigid(picks->pairs);
      report.success = fit.valid;
      report.rms_m = fit.rms_m;
      report.count = fit.pairs;
      report.T_target_source = fit.T_target_source;
      if (!fit.valid) {
        report.failure = "fewer than 3 point pairs, or the picked points lie on a line";
        return {};
      }
      return {{"coarse", fit.T_target_source}};
    }
    case CoarseMethod::kFeatures: {
      report.method = "features";
      const FeatureAlignmentResult aligned =
          align_features(features[static_cast<std::size_t>(source)],
                         features[static_cast<std::size_t>(target)], settings.features);
      report.success = aligned.success;
      report.inlier_ratio = aligned.inlier_ratio;
      report.count = aligned.inliers;
      report.seconds = aligned.seconds;
      report.failure = aligned.failure;
      report.T_target_source = aligned.T_target_source;
      std::vector<Candidate> starts{{"initial", initial}};
      if (aligned.success) starts.push_back({"coarse", aligned.T_target_source});
      return starts;
    }
  }
  return {};
}

// A feature match can agree on a dominant plane (the ground) and nothing
// else; it counts only when enough of the scan lands on the target's surfaces.
void check_coarse_overlap(const SampleCloud& source, const PreparedScan& target,
                          const RegistrationSettings& settings, CoarseReport& report) {
  IcpSettings gate = settings.icp;
  gate.min_gate_m = 0.5 * settings.features.inlier_distance_m;
  const AlignmentQuality quality = measure_alignment(source, target, report.T_target_source, gate);
  report.overlap = quality.overlap;
  report.free_space_violation = quality.free_space_violation;
  if (report.overlap < settings.min_overlap) {
    report.success = false;
    report.failure = "features matched, but only " + std::to_string(report.overlap) +
                     " of the scan overlaps the target at that pose";
  } else if (report.free_space_violation > settings.max_free_space_violation) {
    report.success = false;
    report.failure = "features matched, but that pose puts " +
                     std::to_string(report.free_space_violation) +
                     " of the scan in space the target saw through";
  }
}

// A feature pose counts only when ICP from it ends where the best start
// ended: a wrong match that passed its tests (a façade matched to the wrong
// one, upside-down scenes whose points all hide behind the target's
// surfaces) loses to the start that aligns more of the scan.
void confirm_coarse(const IcpResult& from_coarse, const IcpResult& best, CoarseReport& report) {
  constexpr double kSameRotationRad = 0.01;  // 0.6°
  constexpr double kSameTranslationM = 0.1;
  const auto [rotation, translation] =
      pose_change(from_coarse.T_target_source, best.T_target_source);
  if (rotation <= kSameRotationRad && translation <= kSameTranslationM) return;
  report.success = false;
  report.failure = "features matched, but ICP from the initial pose aligned more of the scan (" +
                   std::to_string(best.overlap) + " against " +
                   std::to_string(from_coarse.overlap) + ")";
}

// Whether ICP from the feature pose can be skipped because the run from the
// initial pose (`best`, registered) already decides it: the feature pose lies
// within a degree and 20 cm of that result (confirmed), or the result aligns
// at least as much of the scan at the coarse stage's tolerance (refused).
bool decided_without_coarse_icp(const IcpResult& best, const SampleCloud& source,
                                const PreparedScan& target, const RegistrationSettings& settings,
                                CoarseReport& report) {
  if (!best.converged || best.overlap < settings.min_overlap ||
      best.free_space_violation > settings.max_free_space_violation) {
    return false;
  }
  constexpr double kSameRotationRad = 0.0175;  // 1°
  constexpr double kSameTranslationM = 0.2;
  const auto [rotation, translation] = pose_change(report.T_target_source, best.T_target_source);
  if (rotation <= kSameRotationRad && translation <= kSameTranslationM) return true;
  IcpSettings gate = settings.icp;
  gate.min_gate_m = 0.5 * settings.features.inlier_distance_m;
  const double overlap = measure_alignment(source, target, best.T_target_source, gate).overlap;
  if (overlap < report.overlap) return false;
  report.success = false;
  report.failure =
      "features matched, but the pose ICP found from the initial pose aligns more "
      "of the scan (" +
      std::to_string(overlap) + " against " + std::to_string(report.overlap) + ")";
  return true;
}

PairReport register_pair(int source, int target, const Eigen::Isometry3d& initial,
                         std::span<const PreparedScan> scans,
                         const std::vector<SampleCloud>& samples,
                         const std::vector<FeatureCloud>& features,
                         const RegistrationSettings& settings) {
  const Clock::time_point start = Clock::now();
  PairReport report;
  report.source = source;
  report.target = target;
  std::vector<Candidate> starts =
      coarse_stage(source, initial, features, settings, target, report.coarse);
  // The coarse pose's tests are decisions on shares: a thinned sample will do.
  const SampleCloud estimate =
      report.coarse.method == "features"
          ? thin(samples[static_cast<std::size_t>(source)], settings.estimate_samples)
          : SampleCloud{};
  if (report.coarse.method == "features" && report.coarse.success) {
    check_coarse_overlap(estimate, scans[static_cast<std::size_t>(target)], settings,
                         report.coarse);
    if (!report.coarse.success) starts.pop_back();
  }
  std::optional<IcpResult> best;
  std::optional<IcpResult> from_coarse;
  for (const Candidate& start : starts) {
    if (start.start == "coarse" && best &&
        decided_without_coarse_icp(*best, estimate, scans[static_cast<std::size_t>(target)],
                                   settings, report.coarse)) {
      continue;
    }
    IcpResult icp = point_to_plane_icp(
        samples[static_cast<std::size_t>(source)], scans[static_cast<std::size_t>(target)],
        start.T_target_source, settings.icp, &samples[static_cast<std::size_t>(target)]);
    if (start.start == "coarse") from_coarse = icp;
    if (!best || better(icp, *best, settings.max_free_space_violation)) {
      best = icp;
      report.start = start.start;
    }
  }
  report.seconds = acquisition::seconds_since(start);
  if (report.coarse.method == "features" && from_coarse) {
    confirm_coarse(*from_coarse, *best, report.coarse);
  }
  if (!best) {
    report.failure = "coarse alignment failed: " + report.coarse.failure;
    return report;
  }
  report.icp = *best;
  report.registered = best->converged && best->overlap >= settings.min_overlap &&
                      best->free_space_violation <= settings.max_free_space_violation;
  if (!best->converged) {
    report.failure = "ICP did not converge";
  } else if (best->overlap < settings.min_overlap) {
    report.failure = "overlap " + std::to_string(best->overlap) + " is below the minimum " +
                     std::to_string(settings.min_overlap);
  } else if (!report.registered) {
    report.failure = "the pose puts " + std::to_string(best->free_space_violation) +
                     " of the scan in space the target saw through (at most " +
                     std::to_string(settings.max_free_space_violation) + ")";
  }
  return report;
}

// Every pair of registered scans that overlaps at the given poses.
std::vector<ScanEdge> overlapping_edges(std::span<const PreparedScan> scans,
                                        const std::vector<SampleCloud>& samples,
                                        const std::vector<Eigen::Isometry3d>& T_first_scan,
                                        const std::vector<bool>& registered,
                                        const RegistrationSettings& settings) {
  std::vector<ScanEdge> edges;
  for (int a = 1; a < static_cast<int>(scans.size()); ++a) {
    for (int b = 0; b < a; ++b) {
      if (!registered[static_cast<std::size_t>(a)] || !registered[static_cast<std::size_t>(b)]) {
        continue;
      }
      const Eigen::Isometry3d T_b_a = T_first_scan[static_cast<std::size_t>(b)].inverse() *
                                      T_first_scan[static_cast<std::size_t>(a)];
      // A decision on a share: a thinned sample will do.
      const AlignmentQuality quality =
          measure_alignment(thin(samples[static_cast<std::size_t>(a)], settings.estimate_samples),
                            scans[static_cast<std::size_t>(b)], T_b_a, settings.icp);
      if (quality.overlap >= settings.min_global_overlap) edges.push_back({a, b});
    }
  }
  return edges;
}

void report_edges(std::span<const PreparedScan> scans, const std::vector<SampleCloud>& samples,
                  const std::vector<Eigen::Isometry3d>& T_first_scan,
                  const std::vector<ScanEdge>& edges, const RegistrationSettings& settings,
                  RegistrationResult& result) {
  double sum_squared = 0.0;
  std::size_t sample_count = 0;
  for (const ScanEdge& edge : edges) {
    const auto a = static_cast<std::size_t>(edge.source);
    const auto b = static_cast<std::size_t>(edge.target);
    const AlignmentQuality quality = measure_alignment(
        samples[a], scans[b], T_first_scan[b].inverse() * T_first_scan[a], settings.icp);
    result.edges.push_back({edge.source, edge.target, quality});
    sum_squared += quality.rms_m * quality.rms_m * static_cast<double>(quality.correspondences);
    result.correspondences += quality.correspondences;
    sample_count += samples[a].size();
  }
  if (result.correspondences > 0) result.rms_m = std::sqrt(sum_squared / result.correspondences);
  if (sample_count > 0) result.overlap = static_cast<double>(result.correspondences) / sample_count;
}

}  // namespace

RegistrationResult register_scans(std::span<const PreparedScan> scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings) {
  assert(scans.size() == initial_T_world_scan.size() && !scans.empty());
  const Clock::time_point start = Clock::now();
  const std::size_t n = scans.size();
  std::vector<SampleCloud> samples;
  std::vector<FeatureCloud> features;
  for (const PreparedScan& scan : scans) {
    samples.push_back(sample_scan(scan, settings.icp_sample));
    if (settings.coarse == CoarseMethod::kFeatures) {
      features.emplace_back(sample_scan(scan, settings.features.sample), settings.features);
    }
  }
  RegistrationResult result;
  result.coarse_seconds = acquisition::seconds_since(start);
  std::vector<Eigen::Isometry3d> T_first_scan(n, Eigen::Isometry3d::Identity());
  std::vector<bool> registered(n, true);
  for (std::size_t k = 1; k < n; ++k) {
    const int source = static_cast<int>(k);
    int target = source - 1;
    const PickedPairs* picks =
        settings.coarse == CoarseMethod::kPointPairs ? picks_for(settings, source) : nullptr;
    if (picks != nullptr) target = picks->target;
    const auto t = static_cast<std::size_t>(target);
    // The start: the source's initial pose against the target where the
    // target registered, so that one scan's initial error does not add to
    // the next one's (with a lever arm as long as the distance between them).
    const Eigen::Isometry3d initial_T_first_source =
        initial_T_world_scan[0].inverse() * initial_T_world_scan[k];
    const Eigen::Isometry3d initial = T_first_scan[t].inverse() * initial_T_first_source;
    PairReport pair = register_pair(source, target, initial, scans, samples, features, settings);
    T_first_scan[k] =
        pair.registered ? T_first_scan[t] * pair.icp.T_target_source : initial_T_first_source;
    registered[k] = pair.registered && registered[t];
    result.iterations += pair.icp.iterations;
    result.coarse_seconds += pair.coarse.seconds;
    result.fine_seconds += pair.seconds - pair.coarse.seconds;
    result.pairs.push_back(std::move(pair));
  }

  const std::vector<ScanEdge> edges =
      overlapping_edges(scans, samples, T_first_scan, registered, settings);
  if (settings.refine_globally && n > 1 && !edges.empty()) {
    result.global = refine_globally(samples, scans, T_first_scan, edges, settings.global);
    T_first_scan = result.global.T_first_scan;
    result.iterations += result.global.rounds;
    result.fine_seconds += result.global.seconds;
  }
  report_edges(scans, samples, T_first_scan, edges, settings, result);

  for (std::size_t k = 0; k < n; ++k) {
    result.T_world_scan.push_back(initial_T_world_scan[0] * T_first_scan[k]);
  }
  result.converged = std::all_of(registered.begin(), registered.end(), [](bool r) { return r; }) &&
                     (!settings.refine_globally || n == 1 || result.global.converged);
  result.seconds = acquisition::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration

#include "registration/register_scans.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <optional>

#include "core/timing.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {
namespace {

using Clock = std::chrono::steady_clock;

struct Candidate {
  IcpStart start;
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

// The coarse stage of one pair: its report, and the starts ICP tries (for
// features only the initial pose; feature_start adds its own).
std::vector<Candidate> coarse_stage(int source, const Eigen::Isometry3d& initial,
                                    const RegistrationSettings& settings, CoarseReport& report) {
  switch (settings.coarse) {
    case CoarseMethod::kNone:
      report.method = CoarseMethod::kNone;
      report.success = true;
      return {{IcpStart::kInitial, initial}};
    case CoarseMethod::kPointPairs: {
      report.method = CoarseMethod::kPointPairs;
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
      return {{IcpStart::kCoarse, fit.T_target_source}};
    }
    case CoarseMethod::kFeatures:
      // The feature pose is added by feature_start, after verification.
      report.method = CoarseMethod::kFeatures;
      return {{IcpStart::kInitial, initial}};
  }
  return {};
}

// The hypotheses ICP verifies: the first verify_by_inliers (most inliers),
// and the verify_by_overlap that put the largest share of a thinned sample
// on the target's surfaces less the share in its free space. The two lists
// fail differently: many inliers can be a façade matched to its neighbour,
// a high overlap a pose that slid along the ground.
std::vector<std::size_t> verification_candidates(std::span<const PoseHypothesis> hypotheses,
                                                 const SampleCloud& estimate,
                                                 const PreparedScan& target,
                                                 const RegistrationSettings& settings) {
  const FeatureSettings& features = settings.features;
  std::vector<std::size_t> chosen;
  for (std::size_t i = 0; i < std::min(hypotheses.size(), features.verify_by_inliers); ++i) {
    chosen.push_back(i);
  }
  const SampleCloud few = thin(estimate, features.screening_samples);
  IcpSettings gate = settings.icp;
  gate.min_gate_m = features.hypotheses.inlier_distance_m;
  std::vector<std::pair<double, std::size_t>> by_overlap;
  for (std::size_t i = 0; i < hypotheses.size(); ++i) {
    const AlignmentQuality quality =
        measure_alignment(few, target, hypotheses[i].T_target_source, gate);
    by_overlap.emplace_back(quality.overlap - quality.free_space_violation, i);
  }
  std::stable_sort(by_overlap.begin(), by_overlap.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t rank = 0; rank < std::min(by_overlap.size(), features.verify_by_overlap);
       ++rank) {
    const std::size_t i = by_overlap[rank].second;
    if (std::find(chosen.begin(), chosen.end(), i) == chosen.end()) chosen.push_back(i);
  }
  return chosen;
}

// The feature stage of one pair: pose hypotheses from matched features, the
// most promising refined by ICP on a thinned sample. The coarse pose is the
// refined hypothesis that lands the largest share of the scan on the
// target's surfaces while passing the pair's tests (converged, min_overlap,
// max_free_space_violation); none passing is a failure, never a guess.
std::optional<Eigen::Isometry3d> feature_start(
    const FeatureCloud& source_features, const FeatureCloud& target_features,
    const SampleCloud& estimate, const PreparedScan& target, const SampleCloud& target_sample,
    const RegistrationSettings& settings, CoarseReport& report) {
  const Clock::time_point start = Clock::now();
  const FeatureAlignmentResult aligned =
      align_features(source_features, target_features, settings.features);
  report.failure = aligned.failure;
  std::optional<IcpResult> best;
  std::size_t best_index = 0;
  double closest_overlap = 0.0;  // of the hypotheses that failed, for the message
  for (const std::size_t i :
       verification_candidates(aligned.hypotheses, estimate, target, settings)) {
    const IcpResult icp = point_to_plane_icp(
        estimate, target, aligned.hypotheses[i].T_target_source, settings.icp, &target_sample);
    const bool passes = icp.converged && icp.overlap >= settings.min_overlap &&
                        icp.free_space_violation <= settings.max_free_space_violation;
    if (!passes) {
      closest_overlap = std::max(closest_overlap, icp.overlap);
    } else if (!best || icp.overlap > best->overlap) {
      best = icp;
      best_index = i;
    }
  }
  report.seconds = core::seconds_since(start);
  if (!best) {
    if (!aligned.hypotheses.empty()) {
      report.failure = "none of " + std::to_string(aligned.hypotheses.size()) +
                       " feature poses holds after ICP (largest overlap " +
                       std::to_string(closest_overlap) +
                       ", each non-converged, below the minimum overlap or in the target's "
                       "free space)";
    }
    return std::nullopt;
  }
  const PoseHypothesis& chosen = aligned.hypotheses[best_index];
  report.success = true;
  report.failure.clear();
  report.count = chosen.inliers;
  report.inlier_ratio = aligned.matches > 0 ? static_cast<double>(chosen.inliers) /
                                                  static_cast<double>(aligned.matches)
                                            : 0.0;
  report.overlap = best->overlap;
  report.free_space_violation = best->free_space_violation;
  report.T_target_source = best->T_target_source;
  return best->T_target_source;
}

// Two ICP results this close are the same minimum reached twice.
bool same_result(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  constexpr double kSameRotationRad = 0.01;  // 0.6°
  constexpr double kSameTranslationM = 0.1;
  const auto [rotation, translation] = pose_change(a, b);
  return rotation <= kSameRotationRad && translation <= kSameTranslationM;
}

// A feature pose counts only when ICP from it ends where the best start
// ended: a wrong match that passed its tests (a façade matched to the wrong
// one, upside-down scenes whose points all hide behind the target's
// surfaces) loses to the start that aligns more of the scan.
void confirm_coarse(const IcpResult& from_coarse, const IcpResult& best, CoarseReport& report) {
  if (same_result(from_coarse.T_target_source, best.T_target_source)) return;
  report.success = false;
  report.failure = "features matched, but ICP from the initial pose aligned more of the scan (" +
                   std::to_string(best.overlap) + " against " +
                   std::to_string(from_coarse.overlap) + ")";
}

// Whether ICP from the feature pose can be skipped because the run from the
// initial pose (`best`, registered) already decides it: the feature pose
// (itself an ICP result on the thinned sample) is that result (confirmed),
// or the result aligns at least as much of the thinned sample (refused).
bool decided_without_coarse_icp(const IcpResult& best, const SampleCloud& source,
                                const PreparedScan& target, const RegistrationSettings& settings,
                                CoarseReport& report) {
  if (!best.converged || best.overlap < settings.min_overlap ||
      best.free_space_violation > settings.max_free_space_violation) {
    return false;
  }
  if (same_result(report.T_target_source, best.T_target_source)) return true;
  const double overlap =
      measure_alignment(source, target, best.T_target_source, settings.icp).overlap;
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
  const auto s = static_cast<std::size_t>(source);
  const auto t = static_cast<std::size_t>(target);
  std::vector<Candidate> starts = coarse_stage(source, initial, settings, report.coarse);
  // The feature poses' tests are decisions on shares: a thinned sample will do.
  const SampleCloud estimate = settings.coarse == CoarseMethod::kFeatures
                                   ? thin(samples[s], settings.estimate_samples)
                                   : SampleCloud{};
  if (settings.coarse == CoarseMethod::kFeatures) {
    if (const std::optional<Eigen::Isometry3d> pose = feature_start(
            features[s], features[t], estimate, scans[t], samples[t], settings, report.coarse)) {
      starts.push_back({IcpStart::kCoarse, *pose});
    }
  }
  std::optional<IcpResult> best;
  std::optional<IcpResult> from_coarse;
  for (const Candidate& start : starts) {
    if (start.start == IcpStart::kCoarse && report.coarse.method == CoarseMethod::kFeatures &&
        best && decided_without_coarse_icp(*best, estimate, scans[t], settings, report.coarse)) {
      continue;
    }
    IcpResult icp =
        point_to_plane_icp(samples[s], scans[t], start.T_target_source, settings.icp, &samples[t]);
    if (start.start == IcpStart::kCoarse) from_coarse = icp;
    if (!best || better(icp, *best, settings.max_free_space_violation)) {
      best = icp;
      report.start = start.start;
    }
  }
  report.seconds = core::seconds_since(start);
  if (report.coarse.method == CoarseMethod::kFeatures && from_coarse) {
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
                                        const RegistrationSettings& settings,
                                        std::size_t& pair_tests) {
  std::vector<ScanEdge> edges;
  for (int a = 1; a < static_cast<int>(scans.size()); ++a) {
    // A decision on a share: a thinned sample will do.
    const SampleCloud estimate =
        thin(samples[static_cast<std::size_t>(a)], settings.estimate_samples);
    for (int b = 0; b < a; ++b) {
      if (!registered[static_cast<std::size_t>(a)] || !registered[static_cast<std::size_t>(b)]) {
        continue;
      }
      const Eigen::Isometry3d T_b_a = T_first_scan[static_cast<std::size_t>(b)].inverse() *
                                      T_first_scan[static_cast<std::size_t>(a)];
      const AlignmentQuality quality =
          measure_alignment(estimate, scans[static_cast<std::size_t>(b)], T_b_a, settings.icp);
      ++pair_tests;
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

// register_scans' progress: one unit per scan made ready, per pair, and
// the global refinement; cancellation is checked after each.
class StageProgress {
 public:
  StageProgress(core::Progress* progress, std::size_t units) : progress_(progress), units_(units) {}

  void step(const std::string& note) {
    if (progress_ == nullptr) return;
    progress_->update({"register", ++done_, units_, note});
    progress_->throw_if_cancelled("register");
  }

 private:
  core::Progress* progress_;
  std::size_t units_;
  std::size_t done_ = 0;
};

// Every scan's ICP samples, and its features when the coarse step uses them.
struct Clouds {
  std::vector<SampleCloud> samples;
  std::vector<FeatureCloud> features;
};

Clouds prepare_clouds(std::span<const PreparedScan> scans, const RegistrationSettings& settings,
                      StageProgress& steps) {
  Clouds clouds;
  for (const PreparedScan& scan : scans) {
    clouds.samples.push_back(sample_scan(scan, settings.icp_sample));
    if (settings.coarse == CoarseMethod::kFeatures) {
      clouds.features.emplace_back(sample_scan(scan, settings.features.sample), settings.features);
    }
    steps.step("features of " + scan.scan->name);
  }
  return clouds;
}

// Every scan's pose in the first scan's frame, and whether it registered
// (with the whole chain to the first scan).
struct Chain {
  std::vector<Eigen::Isometry3d> T_first_scan;
  std::vector<bool> registered;
};

// Registers each scan after the first against its target (the previous
// scan, or the one its picked point pairs name), chaining the poses; adds
// each pair's report, iterations and times to `result`.
Chain register_chain(std::span<const PreparedScan> scans,
                     std::span<const Eigen::Isometry3d> initial_T_world_scan, const Clouds& clouds,
                     const RegistrationSettings& settings, StageProgress& steps,
                     RegistrationResult& result) {
  const std::size_t n = scans.size();
  Chain chain{std::vector<Eigen::Isometry3d>(n, Eigen::Isometry3d::Identity()),
              std::vector<bool>(n, true)};
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
    const Eigen::Isometry3d initial = chain.T_first_scan[t].inverse() * initial_T_first_source;
    PairReport pair =
        register_pair(source, target, initial, scans, clouds.samples, clouds.features, settings);
    chain.T_first_scan[k] =
        pair.registered ? chain.T_first_scan[t] * pair.icp.T_target_source : initial_T_first_source;
    chain.registered[k] = pair.registered && chain.registered[t];
    result.iterations += pair.icp.iterations;
    result.coarse_seconds += pair.coarse.seconds;
    result.fine_seconds += pair.seconds - pair.coarse.seconds;
    result.pairs.push_back(std::move(pair));
    ++result.pair_tests;
    steps.step("registered " + scans[k].scan->name);
  }
  return chain;
}

}  // namespace

const char* coarse_method_name(CoarseMethod method) {
  switch (method) {
    case CoarseMethod::kNone:
      return "none";
    case CoarseMethod::kPointPairs:
      return "point_pairs";
    case CoarseMethod::kFeatures:
      return "features";
  }
  assert(false && "unknown CoarseMethod");
  return "";
}

std::optional<CoarseMethod> coarse_method_from_name(std::string_view name) {
  for (const CoarseMethod method :
       {CoarseMethod::kNone, CoarseMethod::kPointPairs, CoarseMethod::kFeatures}) {
    if (name == coarse_method_name(method)) return method;
  }
  return std::nullopt;
}

const char* icp_start_name(IcpStart start) {
  return start == IcpStart::kCoarse ? "coarse" : "initial";
}

RegistrationResult register_scans(std::span<const PreparedScan> scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings, core::Progress* progress) {
  assert(scans.size() == initial_T_world_scan.size() && !scans.empty());
  const Clock::time_point start = Clock::now();
  const std::size_t n = scans.size();
  StageProgress steps(progress, 2 * n);  // scans made ready, pairs, the global refinement
  const Clouds clouds = prepare_clouds(scans, settings, steps);
  RegistrationResult result;
  result.coarse_seconds = core::seconds_since(start);
  Chain chain = register_chain(scans, initial_T_world_scan, clouds, settings, steps, result);

  const std::vector<ScanEdge> edges = overlapping_edges(
      scans, clouds.samples, chain.T_first_scan, chain.registered, settings, result.pair_tests);
  if (settings.refine_globally && n > 1 && !edges.empty()) {
    result.global =
        refine_globally(clouds.samples, scans, chain.T_first_scan, edges, settings.global);
    chain.T_first_scan = result.global.T_first_scan;
    result.iterations += result.global.rounds;
    result.fine_seconds += result.global.seconds;
  }
  report_edges(scans, clouds.samples, chain.T_first_scan, edges, settings, result);
  steps.step("global refinement");

  for (std::size_t k = 0; k < n; ++k) {
    result.T_world_scan.push_back(initial_T_world_scan[0] * chain.T_first_scan[k]);
  }
  result.converged =
      std::all_of(chain.registered.begin(), chain.registered.end(), [](bool r) { return r; }) &&
      (!settings.refine_globally || n == 1 || result.global.converged);
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration

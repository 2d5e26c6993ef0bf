#include "registration/register_scans.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <optional>
#include <utility>
#include <vector>

#include "core/timing.hpp"
#include "registration/overlap_screening.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/sample_shelf.hpp"

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

// The clouds of one scan of a pair: its ICP samples, and its features when
// the coarse stage uses them.
struct PairSide {
  const SampleCloud* samples = nullptr;
  const FeatureCloud* features = nullptr;
};

PairReport register_pair(int source, int target, const Eigen::Isometry3d& initial,
                         const PairSide& from, const PreparedScan& target_scan, const PairSide& to,
                         const RegistrationSettings& settings) {
  const Clock::time_point start = Clock::now();
  PairReport report;
  report.source = source;
  report.target = target;
  std::vector<Candidate> starts = coarse_stage(source, initial, settings, report.coarse);
  // The feature poses' tests are decisions on shares: a thinned sample will do.
  const SampleCloud estimate = settings.coarse == CoarseMethod::kFeatures
                                   ? thin(*from.samples, settings.estimate_samples)
                                   : SampleCloud{};
  if (settings.coarse == CoarseMethod::kFeatures) {
    if (const std::optional<Eigen::Isometry3d> pose =
            feature_start(*from.features, *to.features, estimate, target_scan, *to.samples,
                          settings, report.coarse)) {
      starts.push_back({IcpStart::kCoarse, *pose});
    }
  }
  std::optional<IcpResult> best;
  std::optional<IcpResult> from_coarse;
  for (const Candidate& start : starts) {
    if (start.start == IcpStart::kCoarse && report.coarse.method == CoarseMethod::kFeatures &&
        best && decided_without_coarse_icp(*best, estimate, target_scan, settings, report.coarse)) {
      continue;
    }
    IcpResult icp = point_to_plane_icp(*from.samples, target_scan, start.T_target_source,
                                       settings.icp, to.samples);
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

// Every scan's pose in the first scan's frame, and whether it registered
// (with the whole chain to the first scan).
struct Chain {
  std::vector<Eigen::Isometry3d> T_first_scan;
  std::vector<bool> registered;
};

// The target of each scan after the first: the previous scan, or the one
// its picked point pairs name.
int target_of(int source, const RegistrationSettings& settings) {
  const PickedPairs* picks =
      settings.coarse == CoarseMethod::kPointPairs ? picks_for(settings, source) : nullptr;
  return picks != nullptr ? picks->target : source - 1;
}

// Registers each scan after the first against its target, chaining the
// poses, with two scans in hand at a time: each scan is sampled when it is
// taken as a source (its features kept for the next pair, whose target it
// is), and its target taken again; its ICP samples go on `samples`. Adds
// each pair's report, iterations and times to `result`.
Chain register_chain(ScanStream& scans, std::span<const Eigen::Isometry3d> initial_T_world_scan,
                     const RegistrationSettings& settings, StageProgress& steps,
                     SampleShelf& samples, RegistrationResult& result) {
  const int n = static_cast<int>(scans.size());
  Chain chain{std::vector<Eigen::Isometry3d>(scans.size(), Eigen::Isometry3d::Identity()),
              std::vector<bool>(scans.size(), true)};
  std::vector<int> order{0};
  for (int k = 1; k < n; ++k) order.insert(order.end(), {k, target_of(k, settings)});
  scans.plan(order);
  const bool with_features = settings.coarse == CoarseMethod::kFeatures;
  std::optional<FeatureCloud> previous_features;
  for (int k = 0; k < n; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    std::shared_ptr<const PreparedScan> source = scans.get(k);
    const Clock::time_point start = Clock::now();
    SampleCloud icp_samples = sample_scan(*source, settings.icp_sample);
    std::optional<FeatureCloud> features;
    if (with_features)
      features.emplace(sample_scan(*source, settings.features.sample), settings.features);
    result.coarse_seconds += core::seconds_since(start);
    samples.put(uk, std::move(icp_samples));
    const std::string name = source->scan->name;
    steps.step("features of " + name);
    source.reset();
    if (k == 0) {
      previous_features = std::move(features);
      continue;
    }
    const int target = target_of(k, settings);
    assert((!with_features || target == k - 1) && "features chain each scan to the one before");
    const auto t = static_cast<std::size_t>(target);
    // The start: the source's initial pose against the target where the
    // target registered, so that one scan's initial error does not add to
    // the next one's (with a lever arm as long as the distance between them).
    const Eigen::Isometry3d initial_T_first_source =
        initial_T_world_scan[0].inverse() * initial_T_world_scan[uk];
    const Eigen::Isometry3d initial = chain.T_first_scan[t].inverse() * initial_T_first_source;
    const std::shared_ptr<const PreparedScan> target_scan = scans.get(target);
    const std::shared_ptr<const SampleCloud> source_samples = samples.get(uk);
    const std::shared_ptr<const SampleCloud> target_samples = samples.get(t);
    PairReport pair = register_pair(
        k, target, initial, {source_samples.get(), features ? &*features : nullptr}, *target_scan,
        {target_samples.get(), previous_features ? &*previous_features : nullptr}, settings);
    chain.T_first_scan[uk] =
        pair.registered ? chain.T_first_scan[t] * pair.icp.T_target_source : initial_T_first_source;
    chain.registered[uk] = pair.registered && chain.registered[t];
    result.iterations += pair.icp.iterations;
    result.coarse_seconds += pair.coarse.seconds;
    result.fine_seconds += pair.seconds - pair.coarse.seconds;
    result.pairs.push_back(std::move(pair));
    ++result.pair_tests;
    previous_features = std::move(features);
    steps.step("registered " + name);
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

RegistrationResult register_scans(ScanStream& scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings, core::Progress* progress) {
  assert(scans.size() == initial_T_world_scan.size() && scans.size() > 0);
  const Clock::time_point start = Clock::now();
  const std::size_t n = scans.size();
  StageProgress steps(progress, 2 * n);  // scans made ready, pairs, the global refinement
  RegistrationResult result;
  SampleShelf samples(n, kSamplesKept);
  Chain chain = register_chain(scans, initial_T_world_scan, settings, steps, samples, result);

  // The target scans of the edges found, as patches around their sources'
  // samples: the global refinement and the report load a target scan only
  // where a pose leaves its patch.
  EdgePatches patches(n);
  const std::vector<ScanEdge> edges = overlapping_edges(
      scans, samples, patches, chain.T_first_scan, chain.registered, settings, result.pair_tests);
  if (settings.refine_globally && n > 1 && !edges.empty()) {
    result.global =
        refine_globally(samples, scans, patches, chain.T_first_scan, edges, settings.global);
    chain.T_first_scan = result.global.T_first_scan;
    result.iterations += result.global.rounds;
    result.fine_seconds += result.global.seconds;
  }
  report_edges(scans, samples, patches, chain.T_first_scan, edges, settings, result);
  result.patch_visits = patches.patch_visits();
  result.scan_visits = patches.scan_visits();
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

RegistrationResult register_scans(std::span<const PreparedScan> scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings, core::Progress* progress) {
  ScansInMemory stream(scans);
  return register_scans(stream, initial_T_world_scan, settings, progress);
}

}  // namespace scanbench::registration

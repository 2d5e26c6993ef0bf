// `scanbench bench registration` (issue #5). Each site's campaign is scanned
// once; every trial perturbs the true poses of all scans but the first by up
// to 5° and 1 m and registers from there. Errors are the rotation angle and
// the translation length of T_true⁻¹ · T_estimated per scan (the first scan is
// the fixed reference, kept at its true pose).
//
// The peer, PCL's IterativeClosestPointWithNormals, aligns each scan to the
// one before it from the same start as our chosen ICP run (the coarse pose
// when the run from it won, else the perturbed pose against where PCL put
// the target), on the same samples; "seconds" compare the fine stages (ours:
// ICP of every pair and the global refinement; PCL: its ICP of every pair),
// per campaign. Our feature stage, with the ICP runs that verify its
// hypotheses, is "coarse_seconds". PCL's ICP runs on one thread, ours on all
// cores; "ours_one_thread" is the same pipeline on one.
#include "bench/bench_registration.hpp"

#include <algorithm>
#include <numbers>
#include <string>
#include <vector>

#include "acquisition/scan_geometry.hpp"
#include "acquisition/simulation/pose_error.hpp"
#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "bench/pcl_icp.hpp"
#include "bench/simulated_site.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/register_scans.hpp"

namespace scanbench::bench {
namespace {

namespace sim = acquisition::sim;
using registration::PreparedScan;

constexpr double kMaxRotationErrorDeg = 5.0;
constexpr double kMaxTranslationErrorM = 1.0;
// A coarse pose this close to the truth lies in ICP's basin: a success.
constexpr double kCoarseBasinDeg = 2.0;
constexpr double kCoarseBasinM = 0.5;

// The simulated site with what both methods start from.
struct SiteScans {
  SimulatedSite site;
  std::vector<PreparedScan> prepared;
  std::vector<registration::SampleCloud> samples;  // PCL's clouds
  const std::vector<Eigen::Isometry3d>& truth() const { return site.true_poses; }
};

SiteScans scan_site(const std::string& name, const sim::ScannerModel& model, int scan_count,
                    const registration::SampleSettings& sample) {
  SiteScans out{simulate_site(name, model, scan_count), {}, {}};
  for (std::size_t k = 0; k < out.site.scans.size(); ++k) {
    out.prepared.push_back(registration::prepare_scan(out.site.scans[k], out.site.geometry[k], 0));
    out.samples.push_back(registration::sample_scan(out.prepared.back(), sample));
  }
  return out;
}

struct MethodErrors {
  std::vector<double> rotation_deg;
  std::vector<double> translation_m;
  double seconds = 0.0;  // summed over trials
  int runs = 0;

  void add(const std::vector<Eigen::Isometry3d>& truth,
           const std::vector<Eigen::Isometry3d>& estimate) {
    for (std::size_t k = 1; k < truth.size(); ++k) {
      const auto [rotation, translation] = registration::pose_change(truth[k], estimate[k]);
      rotation_deg.push_back(rotation * 180.0 / std::numbers::pi);
      translation_m.push_back(translation);
    }
  }
};

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double maximum(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

nlohmann::json errors_json(const MethodErrors& e) {
  return {{"max_rotation_error_deg", maximum(e.rotation_deg)},
          {"max_translation_error_m", maximum(e.translation_m)},
          {"median_rotation_error_deg", median(e.rotation_deg)},
          {"median_translation_error_m", median(e.translation_m)},
          {"seconds", e.runs > 0 ? e.seconds / e.runs : 0.0}};
}

// PCL's ICP along the same chain, from the starts of our chosen ICP runs.
std::vector<Eigen::Isometry3d> pcl_chain(const SiteScans& site,
                                         const std::vector<Eigen::Isometry3d>& initial,
                                         const registration::RegistrationResult& ours,
                                         double& seconds) {
  std::vector<Eigen::Isometry3d> poses{initial[0]};
  for (const registration::PairReport& pair : ours.pairs) {
    const auto s = static_cast<std::size_t>(pair.source);
    const auto t = static_cast<std::size_t>(pair.target);
    // Where our chosen ICP run started: the coarse pose, or the source's
    // initial pose against where PCL put the target.
    const Eigen::Isometry3d start = pair.start == registration::IcpStart::kCoarse
                                        ? pair.coarse.T_target_source
                                        : poses[t].inverse() * initial[s];
    const PclIcpResult icp = pcl_point_to_plane_icp(site.samples[s], site.samples[t], start, {});
    seconds += icp.seconds;
    poses.push_back(poses[t] * icp.T_target_source);
  }
  return poses;
}

struct CoarseTally {
  int pairs = 0;
  int successes = 0;  // accepted and in ICP's basin
  int wrong = 0;      // accepted but outside the basin: silently wrong
};

void tally_coarse(const SiteScans& site, const registration::RegistrationResult& ours,
                  CoarseTally& tally) {
  for (const registration::PairReport& pair : ours.pairs) {
    ++tally.pairs;
    if (!pair.coarse.success) continue;
    const auto s = static_cast<std::size_t>(pair.source);
    const auto t = static_cast<std::size_t>(pair.target);
    const auto [rotation, translation] = registration::pose_change(
        site.truth()[t].inverse() * site.truth()[s], pair.coarse.T_target_source);
    const bool in_basin =
        rotation * 180.0 / std::numbers::pi <= kCoarseBasinDeg && translation <= kCoarseBasinM;
    (in_basin ? tally.successes : tally.wrong) += 1;
  }
}

}  // namespace

nlohmann::json run_registration_bench(const BenchOptions& options) {
  sim::ScannerModel model;
  if (options.smoke) {
    model.columns = 900;
    model.rows = 225;
  }
  const int scan_count = options.smoke ? 2 : 4;
  const int trials_per_site = options.smoke ? 1 : 10;
  const std::vector<std::string> sites = options.smoke
                                             ? std::vector<std::string>{"campus"}
                                             : std::vector<std::string>{"campus", "street"};
  registration::RegistrationSettings settings;
  // The same pipeline on one thread: PCL's ICP runs on one.
  registration::RegistrationSettings one_thread = settings;
  one_thread.icp.threads = one_thread.global.icp.threads = one_thread.features.threads = 1;
  MethodErrors ours;
  MethodErrors ours_one_thread;
  MethodErrors pcl;
  CoarseTally coarse;
  double coarse_seconds = 0.0;
  for (const std::string& name : sites) {
    const SiteScans site = scan_site(name, model, scan_count, settings.icp_sample);
    for (int trial = 0; trial < trials_per_site; ++trial) {
      sim::Random random(sim::hash_combine(0x5245u, static_cast<std::uint64_t>(trial)));
      std::vector<Eigen::Isometry3d> initial = site.truth();
      for (std::size_t k = 1; k < initial.size(); ++k) {
        initial[k] = initial[k] *
                     sim::random_pose_error(kMaxRotationErrorDeg, kMaxTranslationErrorM, random);
      }
      settings.features.hypotheses.seed = static_cast<std::uint64_t>(trial) + 1;
      one_thread.features.hypotheses.seed = settings.features.hypotheses.seed;
      const registration::RegistrationResult result =
          registration::register_scans(site.prepared, initial, settings);
      const registration::RegistrationResult single =
          registration::register_scans(site.prepared, initial, one_thread);
      ours_one_thread.add(site.truth(), single.T_world_scan);
      ours_one_thread.seconds += single.fine_seconds;
      ++ours_one_thread.runs;
      ours.add(site.truth(), result.T_world_scan);
      ours.seconds += result.fine_seconds;
      ++ours.runs;
      coarse_seconds += result.coarse_seconds;
      tally_coarse(site, result, coarse);
      pcl.add(site.truth(), pcl_chain(site, initial, result, pcl.seconds));
      ++pcl.runs;
    }
  }
  nlohmann::json ours_json = errors_json(ours);
  ours_json["coarse_success_rate"] =
      coarse.pairs > 0 ? static_cast<double>(coarse.successes) / coarse.pairs : 0.0;
  ours_json["coarse_accepted_but_wrong"] = coarse.wrong;
  ours_json["coarse_seconds"] = ours.runs > 0 ? coarse_seconds / ours.runs : 0.0;
  ours_json["trials"] = ours.runs;
  nlohmann::json pcl_json = errors_json(pcl);
  return {{"suite", "registration"},
          {"sites", sites},
          {"scans_per_site", scan_count},
          {"columns", model.columns},
          {"rows", model.rows},
          {"max_initial_error",
           {{"rotation_deg", kMaxRotationErrorDeg}, {"translation_m", kMaxTranslationErrorM}}},
          {"ours", ours_json},
          {"pcl_icp_point_to_plane", pcl_json},
          {"ours_one_thread", errors_json(ours_one_thread)},
          {"fine_speedup_vs_pcl", ours.seconds > 0.0 ? pcl.seconds / ours.seconds : 0.0},
          {"fine_speedup_vs_pcl_one_thread",
           ours_one_thread.seconds > 0.0 ? pcl.seconds / ours_one_thread.seconds : 0.0}};
}

}  // namespace scanbench::bench

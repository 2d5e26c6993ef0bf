// `scanbench bench geometry` (issue #4): our grid normals and mixed-pixel
// flags against the simulator's exact per-pixel truth (issue #3), with PCL's
// estimators fed the same organized clouds in the same run.
//
// Accuracy is the sign-agnostic angle to the truth normal. Truth mixed pixels
// are left out of the error statistics: their range is a blend of two
// surfaces, so no estimator can be right there — they are scored as
// detections instead (recall and false rate of kFlagMixedPixel).
//
// Threads: ours runs twice, on every core ("ours") and on one
// ("ours_1_thread"); PCL's integral-image estimator has no threading, so the
// speed goal is judged thread for thread: ours_1_thread against PCL's
// AVERAGE_3D_GRADIENT (its faster variant). The ratios against "ours" are
// all cores against one and are labelled as such.
//
// Noise profiles (issue 27): "noise_profiles" scans the campus once with
// each of the simulator's instruments (pulsed, phase-shift, structured
// light; virtual_scanner.hpp) and runs ours with estimate_range_noise, so
// the estimator is never told which profile made the data; it lists the
// estimated σ(range) against the profile's, and our errors against the best
// PCL variant's on the same scan.
//
// Support: our fit takes the widest clean window of radius 16, 8, 4 or 2
// (33 × 33, 17 × 17, 9 × 9 or 5 × 5 pixels; GeometrySettings), else a
// covariance fit in 5 × 5. PCL's integral image takes a smoothing × smoothing
// window that shrinks to the distance to the nearest depth change. Neither
// support equals the other; the entries "…_smoothing_33" only give PCL a
// window as wide as our widest.
#include "bench/bench_geometry.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/geometry/noise_estimate.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "bench/pcl_normals.hpp"
#include "core/parallel.hpp"
#include "modeling/command_json.hpp"

namespace scanbench::bench {
namespace {

namespace sim = acquisition::sim;
using Normals = std::vector<Eigen::Vector3f>;

constexpr std::uint64_t kSiteSeed = 1;
constexpr int kCampaignScans = 4;  // the site's default campaign; we scan its first poses

// Object kinds built from planes only: their truth normal is constant over
// the object, so their error isolates the estimator from curvature.
constexpr std::array<std::string_view, 7> kPlanarKinds = {"wall", "roof",   "door",    "window",
                                                          "sign", "ground", "low_wall"};

struct Peer {
  const char* key;
  PclNormalSettings settings;
  bool in_issue;  // one of the three peers issue #4 names (goals are judged on these)
};

// PCL settings. Each issue peer runs with the most accurate setting of a sweep
// on campus scan 1 at 3600 × 900 (median error over the scored pixels). The
// median keeps falling as the window grows (most scored pixels lie on large,
// densely sampled planes, where a wider window only averages more noise),
// while coverage falls and edges blur, so "most accurate" is the lowest
// median among settings that keep coverage ≥ 0.9 and a p95 no worse than
// PCL's common setting (tutorial: depth factor 0.02, smoothing 10; k = 16).
// Measured (median / p95 / coverage):
// - Integral image, COVARIANCE_MATRIX: smoothing 10 → 0.50° / 22.5° / 0.943,
//   20 → 0.16° / 19.5° / 0.924, 30 → 0.093° / 15.2° / 0.905 (chosen),
//   40 → 0.069° / 15.3° / 0.886. AVERAGE_3D_GRADIENT: 10 → 0.43° / 23.5°,
//   30 → 0.13° / 16.4° / 0.905 (chosen). Depth factors 0.002–0.01 cut
//   coverage to 0.5–0.9; depth-dependent smoothing was worse in every case:
//   PCL reads z as a camera's depth, and on a panorama z is height.
// - kNN: k = 16 → 2.5° / 13.4°, 30 → 1.3° / 9.2°, 50 → 0.79° / 11.5°
//   (chosen: the lowest median with a p95 below the tutorial's), 80 → 0.52° /
//   16.6°.
// Two extra entries run the integral image with smoothing 33, the side of our
// widest window (radius 16), for a view at PCL's largest window as wide as
// ours. That is not equal support (see the top of the file), and its wider
// border leaves more pixels without a normal.
std::vector<Peer> pcl_peers(int repeats) {
  PclNormalSettings covariance;
  covariance.method = PclNormalMethod::kIntegralCovariance;
  covariance.max_depth_change_factor = 0.02f;
  covariance.normal_smoothing_size = 30.0f;
  covariance.depth_dependent_smoothing = false;
  PclNormalSettings gradient = covariance;
  gradient.method = PclNormalMethod::kIntegralAverage3dGradient;
  PclNormalSettings knn;
  knn.method = PclNormalMethod::kKnnOmp;
  knn.k_neighbours = 50;
  knn.threads = 2;
  const auto widest = static_cast<float>(2 * acquisition::GeometrySettings{}.window_radius + 1);
  PclNormalSettings covariance_33 = covariance, gradient_33 = gradient;
  covariance_33.normal_smoothing_size = gradient_33.normal_smoothing_size = widest;
  std::vector<Peer> peers = {{"pcl_integral_covariance", covariance, true},
                             {"pcl_integral_average_3d_gradient", gradient, true},
                             {"pcl_knn_omp", knn, true},
                             {"pcl_integral_covariance_smoothing_33", covariance_33, false},
                             {"pcl_integral_average_3d_gradient_smoothing_33", gradient_33, false}};
  // Best of `repeats` runs; kNN takes seconds per run, where run-to-run
  // noise matters less, and gets at most two.
  for (Peer& peer : peers) {
    peer.settings.repeats =
        peer.settings.method == PclNormalMethod::kKnnOmp ? std::min(repeats, 2) : repeats;
  }
  return peers;
}

nlohmann::json settings_json(const PclNormalSettings& s) {
  if (s.method == PclNormalMethod::kKnnOmp) return {{"k_neighbours", s.k_neighbours}};
  return {{"max_depth_change_factor", s.max_depth_change_factor},
          {"normal_smoothing_size", s.normal_smoothing_size},
          {"depth_dependent_smoothing", s.depth_dependent_smoothing}};
}

nlohmann::json settings_json(const acquisition::GeometrySettings& s) {
  nlohmann::json settings = nlohmann::json::parse(modeling::settings_to_json(s));
  settings["note"] = "time includes footprints and mixed-pixel flags";
  return settings;
}

struct MethodStats {
  std::vector<float> errors_deg;         // scored pixels (see file comment)
  std::vector<float> planar_errors_deg;  // the scored pixels on kPlanarKinds
  std::size_t valid = 0;                 // valid pixels
  std::size_t with_normal = 0;           // valid pixels given a normal
  double seconds = 0.0;                  // best-of-runs time, summed over scans
};

struct MixedStats {
  std::size_t truth_mixed = 0;  // valid pixels that are truth mixed pixels
  std::size_t recalled = 0;     // … and flagged by ours
  std::size_t clean = 0;        // valid pixels that are not truth mixed pixels
  std::size_t false_flags = 0;  // … but flagged by ours
};

// planar[id] = 1 when object `id` is of a planar kind; indexed by ObjectId.
std::vector<std::uint8_t> planar_objects(const sim::Scene& scene) {
  std::vector<std::uint8_t> planar(scene.objects().size() + 1, 0);
  for (const sim::ObjectInfo& info : scene.objects())
    planar[info.id] = std::ranges::find(kPlanarKinds, info.kind) != kPlanarKinds.end();
  return planar;
}

// Methods mark "no normal" with the zero vector; anything non-finite counts too.
bool has_normal(const Eigen::Vector3f& n) {
  return n.allFinite() && n.squaredNorm() > 0.25f;
}

void accumulate(const sim::SimulatedScan& simulated, const Normals& normals,
                const std::vector<std::uint8_t>& planar, double seconds, MethodStats& stats) {
  const acquisition::Scan& scan = simulated.scan;
  const sim::ScanTruth& truth = simulated.truth;
  constexpr float kDegrees = 180.0f / std::numbers::pi_v<float>;
  stats.seconds += seconds;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    if (!scan.valid[i]) continue;
    ++stats.valid;
    if (!has_normal(normals[i])) continue;
    ++stats.with_normal;
    if (truth.object_id[i] == 0 || truth.mixed[i]) continue;
    const float cosine = std::clamp(std::abs(normals[i].dot(truth.normal_scan[i])), 0.0f, 1.0f);
    const float degrees = std::acos(cosine) * kDegrees;
    stats.errors_deg.push_back(degrees);
    if (planar[truth.object_id[i]]) stats.planar_errors_deg.push_back(degrees);
  }
}

void accumulate_mixed(const sim::SimulatedScan& simulated, const std::vector<std::uint8_t>& flags,
                      MixedStats& stats) {
  for (std::size_t i = 0; i < simulated.scan.pixel_count(); ++i) {
    if (!simulated.scan.valid[i]) continue;
    const bool flagged = (flags[i] & acquisition::kFlagMixedPixel) != 0;
    if (simulated.truth.mixed[i]) {
      ++stats.truth_mixed;
      stats.recalled += flagged;
    } else {
      ++stats.clean;
      stats.false_flags += flagged;
    }
  }
}

struct OursRun {
  Normals normals;  // zero where no normal
  std::vector<std::uint8_t> flags;
  double seconds = 0.0;
};

// compute_geometry with `settings`, best of `repeats` wall times.
OursRun run_ours(const acquisition::Scan& scan, const acquisition::GeometrySettings& settings,
                 int repeats) {
  acquisition::GeometryResult result;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    result = acquisition::compute_geometry(scan, settings);
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count());
  }
  OursRun run{Normals(scan.pixel_count(), Eigen::Vector3f::Zero()),
              std::move(result.geometry.flags), best};
  for (std::size_t i = 0; i < scan.pixel_count(); ++i)
    if (result.geometry.has_normal(i)) run.normals[i] = result.geometry.normal[i];
  return run;
}

// Scan `k` of the campaign, seeded like `scanbench simulate` seeds it.
sim::SimulatedScan simulate(const sim::Site& site, const sim::ScannerModel& model, int k) {
  const std::uint64_t seed = sim::hash_combine(kSiteSeed, static_cast<std::uint64_t>(k) + 1);
  return sim::simulate_scan(site.scene, site.scan_poses[k], model, sim::random_lighting(seed),
                            seed);
}

// The q-quantile (q in [0, 1]) by partial sort; NaN (JSON null) when empty.
double quantile(std::vector<float>& values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto nth = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1));
  std::nth_element(values.begin(), nth, values.end());
  return *nth;
}

double ratio(double numerator, double denominator) {
  return denominator > 0.0 ? numerator / denominator : std::numeric_limits<double>::quiet_NaN();
}

nlohmann::json method_json(MethodStats& stats, int threads, nlohmann::json settings) {
  return {
      {"median_error_deg", quantile(stats.errors_deg, 0.5)},
      {"p95_error_deg", quantile(stats.errors_deg, 0.95)},
      {"planar_median_error_deg", quantile(stats.planar_errors_deg, 0.5)},
      {"coverage", ratio(static_cast<double>(stats.with_normal), static_cast<double>(stats.valid))},
      {"points_per_second", ratio(static_cast<double>(stats.valid), stats.seconds)},
      {"seconds", stats.seconds},
      {"threads", threads},
      {"settings", std::move(settings)}};
}

// Our estimator at default settings on `threads` workers (0 = all cores):
// "ours" and "ours_1_thread". The results do not depend on the thread count;
// each variant is scored on its own output all the same.
struct Ours {
  const char* key;
  acquisition::GeometrySettings settings;
};

std::vector<Ours> our_variants() {
  acquisition::GeometrySettings one_thread;
  one_thread.threads = 1;
  return {{"ours", acquisition::GeometrySettings{}}, {"ours_1_thread", one_thread}};
}

struct OursTotals {
  MethodStats stats;
  MixedStats mixed;
};

struct BenchTotals {
  std::vector<OursTotals> ours;  // one per our_variants()
  std::vector<MethodStats> peers;
};

void bench_scan(const sim::SimulatedScan& simulated, const std::vector<std::uint8_t>& planar,
                const std::vector<Ours>& ours, const std::vector<Peer>& peers, int repeats,
                BenchTotals& totals) {
  for (std::size_t v = 0; v < ours.size(); ++v) {
    const OursRun run = run_ours(simulated.scan, ours[v].settings, repeats);
    accumulate(simulated, run.normals, planar, run.seconds, totals.ours[v].stats);
    accumulate_mixed(simulated, run.flags, totals.ours[v].mixed);
  }
  for (std::size_t p = 0; p < peers.size(); ++p) {
    const PclNormalResult theirs = estimate_pcl_normals(simulated.scan, peers[p].settings);
    accumulate(simulated, theirs.normal, planar, theirs.seconds, totals.peers[p]);
  }
}

// The speed goal of issue #4, judged thread for thread (issue #11): ours on
// one thread at least this many times PCL's AVERAGE_3D_GRADIENT on one.
constexpr double kSpeedupGoal = 5.0;

nlohmann::json goals_json(const nlohmann::json& report, const std::vector<Peer>& peers) {
  bool lower_median = true;
  for (const Peer& peer : peers) {
    if (!peer.in_issue) continue;
    const nlohmann::json& theirs = report[peer.key]["median_error_deg"];
    const nlohmann::json& ours = report["ours"]["median_error_deg"];
    lower_median = lower_median && ours.is_number() &&
                   (!theirs.is_number() || ours.get<double>() < theirs.get<double>());
  }
  const nlohmann::json& speedup = report["speedup_vs_pcl_integral_average_3d_gradient_1_thread"];
  const nlohmann::json& ours = report["ours"];
  return {{"median_below_every_pcl", lower_median},
          {"speedup_1_thread_at_least_5x_vs_average_3d_gradient",
           speedup.is_number() && speedup.get<double>() >= kSpeedupGoal},
          {"mixed_recall_at_least_0_9_false_rate_at_most_0_01",
           ours["mixed_pixel_recall"].get<double>() >= 0.9 &&
               ours["mixed_pixel_false_rate"].get<double>() <= 0.01}};
}

nlohmann::json ours_json(OursTotals& totals, const acquisition::GeometrySettings& settings) {
  nlohmann::json json =
      method_json(totals.stats, core::worker_count(settings.threads), settings_json(settings));
  json["mixed_pixel_recall"] = ratio(static_cast<double>(totals.mixed.recalled),
                                     static_cast<double>(totals.mixed.truth_mixed));
  json["mixed_pixel_false_rate"] =
      ratio(static_cast<double>(totals.mixed.false_flags), static_cast<double>(totals.mixed.clean));
  json["truth_mixed_pixels"] = totals.mixed.truth_mixed;
  return json;
}

double points_per_second(const nlohmann::json& method) {
  return method["points_per_second"].get<double>();
}

// speedup_vs_PEER: "ours" (all cores) against the peer on its threads;
// speedup_vs_PEER_1_thread, for the single-threaded peers: "ours_1_thread".
nlohmann::json report_json(BenchTotals& totals, const std::vector<Ours>& ours,
                           const std::vector<Peer>& peers) {
  nlohmann::json report;
  for (std::size_t v = 0; v < ours.size(); ++v)
    report[ours[v].key] = ours_json(totals.ours[v], ours[v].settings);
  for (std::size_t p = 0; p < peers.size(); ++p) {
    const PclNormalSettings& s = peers[p].settings;
    const int threads = s.method == PclNormalMethod::kKnnOmp ? s.threads : 1;
    const std::string key = peers[p].key;
    report[key] = method_json(totals.peers[p], threads, settings_json(s));
    const double theirs = points_per_second(report[key]);
    report["speedup_vs_" + key] = ratio(points_per_second(report["ours"]), theirs);
    if (threads == 1) {
      report["speedup_vs_" + key + "_1_thread"] =
          ratio(points_per_second(report["ours_1_thread"]), theirs);
    }
  }
  report["speedup_goal_1_thread"] = kSpeedupGoal;
  report["goals"] = goals_json(report, peers);
  return report;
}

// σ(range) estimated from scan `simulated` against the truth it was made
// with, at the ranges of the profile the campus offers.
nlohmann::json sigma_json(const sim::SimulatedScan& simulated, const sim::ScannerModel& model) {
  const acquisition::NoiseEstimate estimate = acquisition::estimate_range_noise(simulated.scan);
  nlohmann::json out = nlohmann::json::array();
  for (const double range : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0}) {
    if (range < model.min_range_m || range > model.max_range_m) continue;
    const double truth = model.range_noise.sigma(range);
    const double estimated = estimate.noise.sigma(range);
    out.push_back({{"range_m", range},
                   {"truth_mm", 1e3 * truth},
                   {"estimated_mm", 1e3 * estimated},
                   {"ratio", estimated / truth}});
  }
  return out;
}

// One noise profile (issue 27): the campus scanned by the profile's
// instrument, our geometry estimating each scan's σ(range) from the scan
// alone (the profile is never passed), PCL's variants on the same scans.
nlohmann::json profile_json(const sim::Site& site, const sim::ScannerModel& base,
                            sim::NoiseProfile profile, int scans,
                            const std::vector<std::uint8_t>& planar,
                            const std::vector<Peer>& peers) {
  const sim::ScannerModel model = sim::with_noise_profile(base, profile);
  acquisition::GeometrySettings estimating;
  estimating.estimate_range_noise = true;
  const std::vector<Ours> ours = {{"ours", estimating}};
  BenchTotals totals;
  totals.ours.resize(1);
  totals.peers.resize(peers.size());
  nlohmann::json sigma = nlohmann::json::array();
  for (int k = 0; k < scans; ++k) {
    const sim::SimulatedScan simulated = simulate(site, model, k);
    bench_scan(simulated, planar, ours, peers, 1, totals);
    sigma.push_back(sigma_json(simulated, model));
  }
  nlohmann::json json;
  json["profile"] = sim::noise_profile_name(profile);
  json["sigma_by_scan"] = std::move(sigma);
  json["ours"] = ours_json(totals.ours.front(), estimating);
  std::string best;
  double best_median = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < peers.size(); ++p) {
    nlohmann::json theirs = method_json(totals.peers[p], 1, settings_json(peers[p].settings));
    const nlohmann::json& median = theirs["median_error_deg"];
    if (median.is_number() && median.get<double>() < best_median) {
      best_median = median.get<double>();
      best = peers[p].key;
    }
    theirs.erase("settings");
    json[peers[p].key] = std::move(theirs);
  }
  const nlohmann::json& mine = json["ours"];
  const double ours_median = mine["median_error_deg"].is_number()
                                 ? mine["median_error_deg"].get<double>()
                                 : std::numeric_limits<double>::quiet_NaN();
  json["best_pcl"] = best;
  json["median_error_vs_best_pcl"] = ratio(ours_median, best_median);
  json["points"] = totals.ours.front().stats.valid;
  json["goals"] = {
      {"coverage_at_least_0_95", mine["coverage"].get<double>() >= 0.95},
      {"median_error_at_most_1_2x_best_pcl", ours_median <= 1.2 * best_median},
      {"mixed_recall_at_least_0_9_false_rate_at_most_0_01",
       mine["mixed_pixel_recall"].is_number() && mine["mixed_pixel_recall"].get<double>() >= 0.9 &&
           mine["mixed_pixel_false_rate"].get<double>() <= 0.01}};
  return json;
}

}  // namespace

nlohmann::json run_geometry_bench(const BenchOptions& options) {
  const sim::Site site = sim::make_site("campus", kSiteSeed, kCampaignScans);
  sim::ScannerModel model;
  if (options.smoke) {
    model.columns = 360;
    model.rows = 90;
  }
  const int scans = options.smoke ? 1 : 2;
  // Best of five: on 2 cores shared with the system, single runs of ours
  // vary by ±10 %.
  const int repeats = options.smoke ? 1 : 5;
  const std::vector<std::uint8_t> planar = planar_objects(site.scene);
  const std::vector<Ours> ours = our_variants();
  const std::vector<Peer> peers = pcl_peers(repeats);
  BenchTotals totals;
  totals.ours.resize(ours.size());
  totals.peers.resize(peers.size());
  for (int k = 0; k < scans; ++k)
    bench_scan(simulate(site, model, k), planar, ours, peers, repeats, totals);

  nlohmann::json report = report_json(totals, ours, peers);
  report["suite"] = "geometry";
  report["site"] = "campus";
  report["columns"] = model.columns;
  report["rows"] = model.rows;
  report["scans"] = scans;
  report["points"] = totals.ours.front().stats.valid;
  // Per instrument: one scan each, one run (accuracy, not speed).
  report["noise_profiles"] = nlohmann::json::array();
  const std::vector<Peer> once = pcl_peers(1);
  for (const sim::NoiseProfile profile : sim::kNoiseProfiles) {
    report["noise_profiles"].push_back(profile_json(site, model, profile, 1, planar, once));
  }
  return report;
}

}  // namespace scanbench::bench

#include "bench/bench_segmentation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <optional>
#include <random>
#include <unordered_map>

#include "bench/pcl_segmentation.hpp"
#include "bench/segmentation_sessions.hpp"
#include "bench/simulated_site.hpp"
#include "modeling/object_carry.hpp"
#include "registration/merge.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/proposals.hpp"
#include "segmentation/segmentation_grid.hpp"

namespace scanbench::bench {
namespace {

namespace sim = acquisition::sim;
using segmentation::Channel;
using segmentation::PixelSet;

constexpr int kMaxOperations = 3;
// Sessions go on past the goal's operations, to report how many an object needs.
constexpr int kMaxOperationsPlayed = 6;
constexpr double kIouGoal = 0.95;
constexpr double kModelIouGoal = 0.9;  // every object, in the merged model
constexpr double kLatencyGoalMs = 16.0;
constexpr std::size_t kLargestRegionOfTheGoal = 1'000'000;

// The kinds segmented, and how many of each: the most visible objects.
constexpr std::array<std::pair<const char*, int>, 10> kQuota = {{{"wall", 3},
                                                                 {"roof", 1},
                                                                 {"door", 1},
                                                                 {"window", 3},
                                                                 {"sign", 1},
                                                                 {"low_wall", 1},
                                                                 {"crown", 2},
                                                                 {"trunk", 1},
                                                                 {"car", 1},
                                                                 {"lamp_post", 2}}};

std::vector<TargetObject> pick_targets(const SimulatedSite& site, std::size_t scan,
                                       const segmentation::SegmentationGrid& grid,
                                       std::size_t min_pixels) {
  const std::vector<sim::ObjectId>& ids = site.truth[scan].object_id;
  std::vector<PixelSet> pixels_of(site.objects.size() + 1);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (grid.usable[i] && ids[i] != 0) pixels_of[ids[i]].push_back(static_cast<std::uint32_t>(i));
  }
  std::vector<TargetObject> targets;
  for (const auto& [kind, count] : kQuota) {
    std::vector<TargetObject> of_kind;
    for (const sim::ObjectInfo& object : site.objects) {
      if (object.kind != kind || pixels_of[object.id].size() < min_pixels) continue;
      of_kind.push_back({object.id, object.name, object.kind, pixels_of[object.id]});
    }
    std::stable_sort(of_kind.begin(), of_kind.end(), [](const auto& a, const auto& b) {
      return a.pixels.size() > b.pixels.size();
    });
    of_kind.resize(std::min<std::size_t>(of_kind.size(), static_cast<std::size_t>(count)));
    for (TargetObject& target : of_kind) targets.push_back(std::move(target));
  }
  return targets;
}

double percentile(std::vector<double> values, double share) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::ptrdiff_t>(share * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<std::size_t>(k)];
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Click latencies, split at the goal's region size.
struct Clicks {
  std::vector<double> milliseconds;            // regions up to the goal's size
  std::vector<double> over_goal_milliseconds;  // the others
  std::size_t largest_region = 0;

  void add(const Click& click) {
    largest_region = std::max(largest_region, click.pixels);
    (click.pixels > kLargestRegionOfTheGoal ? over_goal_milliseconds : milliseconds)
        .push_back(1e3 * click.seconds);
  }
};

// Clicks at random usable pixels on every channel, nothing constrained: the
// latency of regions of every size the scan holds.
void random_clicks(const segmentation::SegmentationGrid& grid, segmentation::RegionGrower& grower,
                   int count, Clicks& clicks) {
  const std::vector<std::uint8_t> open = segmentation::open_pixels(grid, {}, {});
  std::vector<std::uint32_t> usable;
  for (std::size_t i = 0; i < grid.usable.size(); ++i) {
    if (grid.usable[i]) usable.push_back(static_cast<std::uint32_t>(i));
  }
  std::mt19937 random(13);
  std::uniform_int_distribution<std::size_t> pick(0, usable.size() - 1);
  constexpr std::array<Channel, 4> kChannels = {Channel::kRange, Channel::kColor,
                                                Channel::kIntensity, Channel::kNormal};
  for (int k = 0; k < count; ++k) {
    const auto settings = segmentation::default_grow_settings(kChannels[k % 4]);
    const auto start = std::chrono::steady_clock::now();
    const segmentation::GrowResult grown = grower.grow(usable[pick(random)], settings, open);
    clicks.add({seconds_since(start), grown.pixels.size()});
  }
}

// The merged model of the site's scans at their true poses, for the IoU of
// an object in the model: the scans prepared, their grids, keep masks, the
// truth.
struct MergedModel {
  const SimulatedSite* site = nullptr;
  std::vector<registration::PreparedScan> prepared;
  std::vector<segmentation::SegmentationGrid> grids;
  std::vector<std::vector<std::uint8_t>> keep;

  explicit MergedModel(const SimulatedSite& s) : site(&s) {
    for (std::size_t k = 0; k < s.scans.size(); ++k) {
      prepared.push_back(registration::prepare_scan(s.scans[k], s.geometry[k], 0));
      grids.push_back(segmentation::prepare_grid(s.scans[k], s.geometry[k], {}));
    }
    registration::MergeResult merged =
        registration::merge_by_sampling_rate(prepared, s.true_poses, {});
    for (registration::MergeScanResult& scan : merged.scans) keep.push_back(std::move(scan.keep));
  }

  // The IoU, over every scan's kept points, of the object drawn as `region`
  // with `grow` in scan `drawn` (which the other scans take as a commit
  // does: modeling::carry_object; none: without growth) against the truth's
  // object `id`.
  double iou(std::size_t drawn, const PixelSet& region,
             const std::optional<segmentation::GrowSettings>& grow, std::uint16_t id) const {
    std::vector<std::uint32_t> labels(prepared[drawn].in_model.size(), 0);
    for (const std::uint32_t i : region) labels[i] = 1;
    modeling::CarrySettings carry;
    carry.grow = grow;
    const modeling::DrawnObject object{&prepared[drawn], site->true_poses[drawn], labels};
    std::size_t both = 0, either = 0;
    for (std::size_t k = 0; k < prepared.size(); ++k) {
      std::vector<std::uint8_t> in_object(prepared[k].in_model.size(), 0);
      if (k == drawn) {
        for (const std::uint32_t i : region) in_object[i] = 1;
      } else {
        const std::vector<std::uint8_t>& open = grids[k].usable;
        for (const std::uint32_t i : modeling::carry_object(
                 object, {&prepared[k], site->true_poses[k], &grids[k], open}, carry))
          in_object[i] = 1;
      }
      const std::vector<sim::ObjectId>& truth = site->truth[k].object_id;
      for (std::size_t i = 0; i < in_object.size(); ++i) {
        if (!keep[k][i]) continue;
        const bool predicted = in_object[i] != 0, true_ = truth[i] == id;
        both += predicted && true_;
        either += predicted || true_;
      }
    }
    return either == 0 ? 0.0 : static_cast<double>(both) / static_cast<double>(either);
  }
};

// The sessions of every target on one scan: the objects' JSON, their mean
// IoU and how many reach the goal within its operations; with a model, the
// same in the merged model.
struct Sessions {
  nlohmann::json objects = nlohmann::json::array();
  double mean_iou = 0.0;
  int reached = 0;
  double mean_model_iou = 0.0;
  int model_reached = 0;  // objects with a model IoU of at least 0.9
  double mean_model_iou_transfer_only = 0.0;
};

Sessions play_sessions(const segmentation::SegmentationGrid& grid,
                       const std::vector<TargetObject>& targets, Clicks* clicks,
                       const MergedModel* model = nullptr, std::size_t scan = 0) {
  segmentation::RegionGrower grower(grid);
  Sessions out;
  for (const TargetObject& target : targets) {
    const Recipe recipe = recipe_for(target.kind);
    const SessionResult session = play_session(grid, grower, target, recipe, kMaxOperationsPlayed);
    // The IoU within the goal's operations, and the operations the goal's IoU took.
    double within = 0.0;
    int operations = 0;
    nlohmann::json needed = nullptr;
    for (const auto& [made, reached_iou] : session.progress) {
      if (made <= kMaxOperations) within = reached_iou, operations = made;
      if (needed.is_null() && reached_iou >= kIouGoal) needed = made;
    }
    if (clicks) {
      for (const Click& click : session.clicks) clicks->add(click);
    }
    out.objects.push_back({{"name", target.name},
                           {"kind", target.kind},
                           {"channel", segmentation::channel_name(recipe.grow.channel)},
                           {"iou", within},
                           {"operations", operations},
                           {"operations_to_0_95", needed},
                           {"pixels", target.pixels.size()}});
    out.mean_iou += within / static_cast<double>(targets.size());
    out.reached += within >= kIouGoal;
    if (model != nullptr) {
      // The region the goal's operations reached, as a commit would store it.
      const PixelSet region = play_session(grid, grower, target, recipe, kMaxOperations).region;
      const double model_iou = model->iou(scan, region, recipe.grow, target.id);
      out.objects.back()["model_iou"] = model_iou;
      const double transfer_only = model->iou(scan, region, std::nullopt, target.id);
      out.objects.back()["model_iou_transfer_only"] = transfer_only;
      out.mean_model_iou_transfer_only += transfer_only / static_cast<double>(targets.size());
      out.mean_model_iou += model_iou / static_cast<double>(targets.size());
      out.model_reached += model_iou >= kModelIouGoal;
    }
  }
  return out;
}

// A segmentation of the whole scan (one label per pixel, −1 = none), each
// target scored by its best-matching segment.
nlohmann::json whole_scan_json(const PclSegmentationResult& result,
                               const std::vector<TargetObject>& targets, nlohmann::json settings) {
  std::unordered_map<std::int32_t, std::size_t> segment_size;
  for (const std::int32_t label : result.label) {
    if (label >= 0) ++segment_size[label];
  }
  nlohmann::json objects = nlohmann::json::array();
  double sum = 0.0;
  for (const TargetObject& target : targets) {
    std::unordered_map<std::int32_t, std::size_t> common;
    for (const std::uint32_t p : target.pixels) {
      if (result.label[p] >= 0) ++common[result.label[p]];
    }
    double best = 0.0;
    for (const auto& [label, shared] : common) {
      const double either =
          static_cast<double>(segment_size[label] + target.pixels.size() - shared);
      best = std::max(best, static_cast<double>(shared) / either);
    }
    objects.push_back({{"name", target.name}, {"iou", best}});
    sum += best;
  }
  return {{"seconds", result.seconds},
          {"mean_iou", targets.empty() ? 0.0 : sum / static_cast<double>(targets.size())},
          {"segments", result.segments},
          {"objects", objects},
          {"settings", std::move(settings)}};
}

nlohmann::json run_pcl(const SimulatedSite& site, const segmentation::SegmentationGrid& grid,
                       const std::vector<TargetObject>& targets, PclSegmenter segmenter) {
  PclSegmentationSettings settings;
  settings.segmenter = segmenter;
  nlohmann::json described;
  if (segmenter == PclSegmenter::kRegionGrowing) {
    described = {{"neighbours", settings.neighbours},
                 {"smoothness_deg", settings.smoothness_deg},
                 {"curvature_test", settings.curvature_threshold > 0.0f},
                 {"normals", "ours"}};
  } else {
    described = {{"distance_m", settings.distance_m},
                 {"point_color_threshold", settings.point_color_threshold},
                 {"region_color_threshold", settings.region_color_threshold}};
  }
  described["min_cluster_size"] = settings.min_cluster_size;
  const PclSegmentationResult result =
      segment_with_pcl(site.scans[0], site.geometry[0], grid.usable, settings);
  return whole_scan_json(result, targets, described);
}

// Our automatic proposals, scored as PCL's segments are.
// `prepare_seconds` (the grid, one thread) counts: PCL's time includes its
// kd-tree.
nlohmann::json run_proposals(const SimulatedSite& site, const segmentation::SegmentationGrid& grid,
                             const std::vector<TargetObject>& targets, double prepare_seconds) {
  const segmentation::ProposalSettings settings;
  const std::vector<std::uint8_t> open = segmentation::open_pixels(grid, {}, {});
  const segmentation::ProposalResult proposals =
      segmentation::propose_regions(grid, open, site.geometry[0].confidence, settings);
  PclSegmentationResult labelled;
  labelled.label.assign(grid.usable.size(), -1);
  for (std::size_t k = 0; k < proposals.regions.size(); ++k) {
    for (const std::uint32_t p : proposals.regions[k])
      labelled.label[p] = static_cast<std::int32_t>(k);
  }
  labelled.segments = proposals.regions.size();
  labelled.seconds = prepare_seconds + proposals.seconds;
  return whole_scan_json(labelled, targets,
                         {{"channel", segmentation::channel_name(settings.grow.channel)},
                          {"tolerance_deg", settings.grow.tolerance},
                          {"min_pixels", settings.min_pixels},
                          {"threads", 1}});
}

segmentation::SegmentationGrid prepare_one_thread(const SimulatedSite& site, std::size_t scan) {
  segmentation::GridSettings settings;
  settings.threads = 1;
  return segmentation::prepare_grid(site.scans[scan], site.geometry[scan], settings);
}

constexpr const char* kProtocol =
    "Oracle-assisted sessions: per object, a user's script (the kind's channel and tolerance, "
    "chosen on scan 1; a lasso around the object's truth extent with a margin, and a barrier "
    "traced one pixel below its foot for posts and the car; a click at its most interior "
    "pixel, then clicks into the largest missed part). The script places these from the "
    "truth, as a user's eyes would; the grower never reads the truth. iou is what 3 "
    "operations reach; the session goes on to 6 to report operations_to_0_95. ours_held_out "
    "plays the same recipes on scan 2. IoU over the scan's usable pixels. model_iou: the "
    "region after 3 operations in scan 1, carried into the other scans as a commit does "
    "(projective association and same-surface test, then growth on the recipe's channel where "
    "scan 1 never sampled the place, within the object's box widened by 25 %), scored over "
    "every scan's points that the merge keeps, at the true poses; model_iou_transfer_only "
    "without the growth. ours_auto and PCL "
    "segment the whole scan with our normals, every object scored by its best-matching "
    "segment (one segment may match several objects). Latency: the sessions' clicks and 400 "
    "random clicks on all channels, one thread, split at regions of 1 M pixels.";

// Our sessions on scan 1 and the clicks' latency.
nlohmann::json ours_json(const Sessions& sessions, const Clicks& clicks, double prepare_seconds) {
  std::vector<double> all_clicks = clicks.milliseconds;
  all_clicks.insert(all_clicks.end(), clicks.over_goal_milliseconds.begin(),
                    clicks.over_goal_milliseconds.end());
  return {{"objects", sessions.objects},
          {"mean_iou", sessions.mean_iou},
          {"objects_at_least_0_95", sessions.reached},
          {"mean_model_iou", sessions.mean_model_iou},
          {"mean_model_iou_transfer_only", sessions.mean_model_iou_transfer_only},
          {"objects_model_iou_at_least_0_9", sessions.model_reached},
          {"click_latency_ms_p50", percentile(clicks.milliseconds, 0.5)},
          {"click_latency_ms_p95", percentile(clicks.milliseconds, 0.95)},
          {"clicks", clicks.milliseconds.size()},
          {"clicks_over_1m_pixels", clicks.over_goal_milliseconds.size()},
          {"click_latency_ms_p95_over_1m_pixels",
           percentile(clicks.over_goal_milliseconds, 0.95)},
          {"click_latency_ms_p95_all", percentile(all_clicks, 0.95)},
          {"largest_region_pixels", clicks.largest_region},
          {"prepare_seconds", prepare_seconds}};
}

}  // namespace

nlohmann::json run_segmentation_bench(const BenchOptions& options) {
  sim::ScannerModel model;
  if (options.smoke) {
    model.columns = 900;
    model.rows = 225;
  }
  const std::size_t min_pixels = options.smoke ? 20 : 200;
  const SimulatedSite site = simulate_site("campus", model, 2);
  const auto prepare_start = std::chrono::steady_clock::now();
  const segmentation::SegmentationGrid grid = prepare_one_thread(site, 0);
  const double prepare_seconds = seconds_since(prepare_start);
  const std::vector<TargetObject> targets = pick_targets(site, 0, grid, min_pixels);

  const MergedModel merged(site);
  Clicks clicks;
  const Sessions sessions = play_sessions(grid, targets, &clicks, &merged, 0);
  segmentation::RegionGrower grower(grid);
  random_clicks(grid, grower, options.smoke ? 20 : 400, clicks);
  const double p95 = percentile(clicks.milliseconds, 0.95);
  const nlohmann::json ours = ours_json(sessions, clicks, prepare_seconds);

  const segmentation::SegmentationGrid held_out_grid = prepare_one_thread(site, 1);
  const Sessions held_out =
      play_sessions(held_out_grid, pick_targets(site, 1, held_out_grid, min_pixels), nullptr);
  return {{"suite", "segmentation"},
          {"site", "campus"},
          {"scan", 1},
          {"columns", model.columns},
          {"rows", model.rows},
          {"protocol", kProtocol},
          {"ours", ours},
          {"ours_held_out",
           {{"scan", 2},
            {"objects", held_out.objects},
            {"mean_iou", held_out.mean_iou},
            {"objects_at_least_0_95", held_out.reached}}},
          {"ours_auto", run_proposals(site, grid, targets, prepare_seconds)},
          {"pcl_region_growing", run_pcl(site, grid, targets, PclSegmenter::kRegionGrowing)},
          {"pcl_region_growing_rgb", run_pcl(site, grid, targets, PclSegmenter::kRegionGrowingRgb)},
          {"goals",
           {{"every_object_iou_at_least_0_95_within_3_operations",
             !targets.empty() && sessions.reached == static_cast<int>(targets.size())},
            {"click_latency_p95_at_most_16_ms", p95 <= kLatencyGoalMs},
            {"mean_model_iou_at_least_0_95", sessions.mean_model_iou >= 0.95},
            {"every_object_model_iou_at_least_0_9",
             !targets.empty() && sessions.model_reached == static_cast<int>(targets.size())}}}};
}

}  // namespace scanbench::bench

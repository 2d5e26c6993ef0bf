// `scanbench bench merge` (issues #5, #11). The campus campaign is merged
// twice: at its true poses, and at the poses our registration finds from
// perturbed ones (every scan but the first off by up to 5° and 1 m, seeded as
// trial 0 of bench "registration"). Both merges are judged against the same
// truth: the simulator's noise-free ranges, object ids and normals per pixel,
// at the true poses. Points are compared at their noise-free positions, so
// the measures see which samples the keep masks keep, not range noise or
// registration error.
//
// Local spacing. The true spacing of pixel k of scan o is its long step: the
// larger of d_col, the mean distance from k's truth point to those of its
// left and right neighbours that show the same object, and d_row, the same
// for the rows above and below (where neither neighbour does, the head-on
// step, range × angle step). Every spot of an unbroken grid lies within
// half its cell's diagonal, at most 0.71 × its long step, of a sample,
// whatever the cell's aspect. A scan "samples a spot" (a truth point X of
// object id, of scan s) when it has a truth sample of id, not a mixed pixel,
// within the spot's own spacing of X (searched in the 5 × 5 pixels around
// X's projection into it).
//
// - coverage_before / coverage_after: of the truth samples (every second row
//   and column of every scan: object id ≠ 0, not a truth mixed pixel), the
//   share still on the model. Sample i of scan s is covered when its own
//   pixel is in the model (before) or kept (after), or when another scan
//   has an in-model (before) or kept (after) point of the same object within
//   0.75 × the finest spacing at the spot (the smallest of s's and those of
//   the other scans' samples there). Neighbours in s's own grid never count:
//   when the merge drops s's point, the spot stays covered only if another
//   scan's kept point stands in for it. A merge that keeps the whole grid of
//   the finest scan loses nothing; one that drops points for samples of a
//   different surface, for samples that are themselves dropped, or for a
//   grid coarser than the finest there (by more than 6 % for square cells)
//   loses spots.
// - redundant_removed_share (the merge's own rule with truth values): of the
//   in-model points whose surface another scan sampled more finely — same
//   object under that scan's beam at the same true range, and a true sample
//   area (r² Ω / |cos θ| with the true range and normal) smaller by more
//   than the merge's tie tolerance — the share the keep masks drop.
// - redundant_removed_share_by_spacing (independent of the merge's rule: no
//   projection test on measured ranges, no sample-area formula, no estimated
//   normal): of the in-model points (not truth mixed pixels) whose spot
//   another scan samples with a true spacing finer by more than 5 %, the
//   share dropped. The merge compares sample areas; where a scan sees a
//   surface obliquely its area can be the smaller while its long step is
//   the larger, so the two measures differ there by design.
//   unique_removed_share: of the in-model points whose spot no other scan
//   samples at all, the share dropped (each one is surface lost).
// - points_per_second: in-model points decided per second by
//   merge_by_sampling_rate, on all cores (preparing the scans, shared with
//   registration, is reported apart); the best of three runs.
#include "bench/bench_merge.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <variant>
#include <vector>

#include "acquisition/simulation/pose_error.hpp"
#include "acquisition/simulation/random.hpp"
#include "bench/simulated_site.hpp"
#include "core/parallel.hpp"
#include "registration/merge.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/register_scans.hpp"

namespace scanbench::bench {
namespace {

namespace sim = acquisition::sim;
using registration::PreparedScan;
using Masks = std::vector<std::vector<std::uint8_t>>;  // per scan, per pixel

constexpr float kCoverageRadiusPerSpacing = 0.75f;
// Spacings within this relative difference: neither scan is truly finer.
constexpr float kTruthTie = 0.05f;
// Pixels searched around a spot's projection into another scan (±): a
// spacing spans up to 2 pixels of an elongated cell's short side.
constexpr int kSpotWindow = 2;
// The registered merge starts registration like trial 0 of bench "registration".
constexpr double kMaxRotationErrorDeg = 5.0;
constexpr double kMaxTranslationErrorM = 1.0;

// One scan's truth as the measures read it: noise-free points in the scan
// frame (zero where no return) and their true local spacing [m] (0 there).
struct TruthGrid {
  std::vector<Eigen::Vector3f> point;
  std::vector<float> spacing_m;
  bool wraps = false;  // the panorama closes the circle: columns wrap
};

struct Truth {
  const SimulatedSite& site;
  std::span<const PreparedScan> prepared;
  std::vector<TruthGrid> grids;
  std::vector<Eigen::Isometry3f> T_world_scan;  // true poses
  std::vector<Eigen::Isometry3f> T_scan_world;
};

// Column `col` moved into the grid (wrapping panoramas), or -1 outside.
int column_in(const TruthGrid& grid, int columns, int col) {
  if (col >= 0 && col < columns) return col;
  if (!grid.wraps) return -1;
  return (col + columns) % columns;
}

// Mean distance from the truth point of pixel i to those of the two pixels
// (row, col ± 1) or (row ± 1, col) that show the same object; `fallback` when
// neither does.
float mean_step(const SimulatedSite& site, const TruthGrid& grid, std::size_t s, std::size_t i,
                int row, int col, bool along_row, float fallback) {
  const acquisition::Scan& scan = site.scans[s];
  float sum = 0.0f;
  int count = 0;
  for (const int step : {-1, 1}) {
    const int r = along_row ? row : row + step;
    const int c = along_row ? column_in(grid, scan.columns, col + step) : col;
    if (r < 0 || r >= scan.rows || c < 0) continue;
    const std::size_t k = scan.index(r, c);
    if (site.truth[s].object_id[k] != site.truth[s].object_id[i]) continue;
    sum += (grid.point[k] - grid.point[i]).norm();
    ++count;
  }
  return count > 0 ? sum / static_cast<float>(count) : fallback;
}

TruthGrid truth_grid(const SimulatedSite& site, std::size_t s) {
  const acquisition::Scan& scan = site.scans[s];
  const sim::ScanTruth& truth = site.truth[s];
  const auto& angles = std::get<acquisition::SphericalAngles>(scan.angles);
  const double azimuth_step = std::abs(angles.azimuth_step_rad);
  TruthGrid grid;
  grid.wraps = std::abs(scan.columns * azimuth_step - 2.0 * std::numbers::pi) < 0.5 * azimuth_step;
  grid.point.assign(scan.pixel_count(), Eigen::Vector3f::Zero());
  grid.spacing_m.assign(scan.pixel_count(), 0.0f);
  core::parallel_for_index(scan.rows, 0, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (truth.object_id[i] != 0)
        grid.point[i] = truth.range_m[i] * acquisition::direction(scan, row, col);
    }
  });
  core::parallel_for_index(scan.rows, 0, [&](int row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (truth.object_id[i] == 0) continue;
      const Eigen::Vector3f& p = grid.point[i];
      const float cos_elevation = std::hypot(p.x(), p.y()) / p.norm();
      const float head_on_column =
          truth.range_m[i] * static_cast<float>(azimuth_step) * std::max(cos_elevation, 1e-3f);
      const float head_on_row =
          truth.range_m[i] * static_cast<float>(std::abs(angles.elevation_step_rad));
      const float d_col = mean_step(site, grid, s, i, row, col, true, head_on_column);
      const float d_row = mean_step(site, grid, s, i, row, col, false, head_on_row);
      grid.spacing_m[i] = std::max(d_col, d_row);
    }
  });
  return grid;
}

Truth make_truth(const SimulatedSite& site, std::span<const PreparedScan> prepared) {
  Truth truth{site, prepared, {}, {}, {}};
  for (std::size_t s = 0; s < site.scans.size(); ++s) {
    truth.grids.push_back(truth_grid(site, s));
    truth.T_world_scan.push_back(site.true_poses[s].cast<float>());
    truth.T_scan_world.push_back(site.true_poses[s].inverse().cast<float>());
  }
  return truth;
}

// A truth sample of another scan near a spot.
struct Neighbour {
  std::size_t scan = 0;
  std::size_t pixel = 0;
  float distance_m = 0.0f;
  float spacing_m = 0.0f;
};

// Calls visit(Neighbour) for every truth sample of scan o that shows object
// `id`, is not a truth mixed pixel, lies within `max_distance` [m] of the
// world point `world`, in the (2 · window + 1)² pixels around its projection.
template <typename Visit>
void visit_neighbours(const Truth& t, std::size_t o, const Eigen::Vector3f& world, sim::ObjectId id,
                      float max_distance, int window, Visit&& visit) {
  const Eigen::Vector3f p = t.T_scan_world[o] * world;
  const std::int64_t pixel = registration::associate(t.prepared[o], p);
  if (pixel < 0) return;
  const acquisition::Scan& scan = t.site.scans[o];
  const sim::ScanTruth& truth = t.site.truth[o];
  const TruthGrid& grid = t.grids[o];
  const int row = static_cast<int>(pixel / scan.columns);
  const int col = static_cast<int>(pixel % scan.columns);
  for (int r = std::max(0, row - window); r <= std::min(scan.rows - 1, row + window); ++r) {
    for (int dc = -window; dc <= window; ++dc) {
      const int c = column_in(grid, scan.columns, col + dc);
      if (c < 0) continue;
      const std::size_t k = scan.index(r, c);
      if (truth.object_id[k] != id || truth.mixed[k]) continue;
      const float distance = (grid.point[k] - p).norm();
      if (distance <= max_distance) visit(Neighbour{o, k, distance, grid.spacing_m[k]});
    }
  }
}

// --- The merge's own rule with truth values (redundant_removed_share) ---

// True surface area per sample: r² · Ω / |cos incidence| (as PreparedScan).
float truth_area(const Truth& t, std::size_t s, std::size_t i) {
  const acquisition::Scan& scan = t.site.scans[s];
  const PreparedScan& prepared = t.prepared[s];
  const float range = t.site.truth[s].range_m[i];
  const float measured = scan.range_m[i];
  // The prepared area with the true range and normal in place of the estimates.
  const Eigen::Vector3f d = t.grids[s].point[i].normalized();
  const float cos_true = std::max(std::abs(t.site.truth[s].normal_scan[i].dot(d)), 0.05f);
  const Eigen::Vector3f n = t.site.geometry[s].normal[i];
  const float cos_est = prepared.usable[i] ? std::max(std::abs(n.dot(d)), 0.05f) : 1.0f;
  const float omega = prepared.sample_area_m2[i] * cos_est / (measured * measured);
  return range * range * omega / cos_true;
}

bool redundant_by_merge_rule(const Truth& t, std::size_t s, std::size_t i, double tie_tolerance) {
  const Eigen::Vector3f world = t.T_world_scan[s] * t.grids[s].point[i];
  const float area = truth_area(t, s, i);
  for (std::size_t o = 0; o < t.prepared.size(); ++o) {
    if (o == s) continue;
    const Eigen::Vector3f p = t.T_scan_world[o] * world;
    const std::int64_t pixel = registration::associate(t.prepared[o], p);
    if (pixel < 0) continue;
    const auto k = static_cast<std::size_t>(pixel);
    if (t.site.truth[o].object_id[k] != t.site.truth[s].object_id[i]) continue;
    if (std::abs(t.site.truth[o].range_m[k] - p.norm()) >
        0.05f + 2.0f * t.site.geometry[o].footprint_m[k]) {
      continue;
    }
    if (truth_area(t, o, k) < area / (1.0 + tie_tolerance)) return true;
  }
  return false;
}

// --- Per point and per sample ---

// What the truth says about in-model point i of scan s.
struct PointTruth {
  bool redundant_by_rule = false;     // the merge's rule with truth values
  bool redundant_by_spacing = false;  // another scan samples its spot finer
  bool unique = false;                // no other scan samples its spot
};

PointTruth point_truth(const Truth& t, std::size_t s, std::size_t i, double tie_tolerance) {
  PointTruth out;
  out.redundant_by_rule = redundant_by_merge_rule(t, s, i, tie_tolerance);
  const Eigen::Vector3f world = t.T_world_scan[s] * t.grids[s].point[i];
  const float spacing = t.grids[s].spacing_m[i];
  bool seen = false;
  for (std::size_t o = 0; o < t.prepared.size(); ++o) {
    if (o == s) continue;
    visit_neighbours(t, o, world, t.site.truth[s].object_id[i], spacing, kSpotWindow,
                     [&](const Neighbour& n) {
                       seen = true;
                       out.redundant_by_spacing |= n.spacing_m < spacing / (1.0f + kTruthTie);
                     });
  }
  out.unique = !seen;
  return out;
}

// Which of `masks` (one per merge, in-model first) cover truth sample i of
// scan s, as bits. `near` is scratch space.
unsigned covered_by(const Truth& t, std::span<const Masks* const> masks, std::size_t s,
                    std::size_t i, std::vector<Neighbour>& near) {
  const Eigen::Vector3f world = t.T_world_scan[s] * t.grids[s].point[i];
  const sim::ObjectId id = t.site.truth[s].object_id[i];
  const float spacing = t.grids[s].spacing_m[i];
  near.clear();
  float finest = spacing;
  for (std::size_t o = 0; o < t.prepared.size(); ++o) {
    if (o == s) continue;
    visit_neighbours(t, o, world, id, spacing, kSpotWindow, [&](const Neighbour& n) {
      near.push_back(n);
      finest = std::min(finest, n.spacing_m);
    });
  }
  const float radius = kCoverageRadiusPerSpacing * finest;
  unsigned bits = 0;
  for (std::size_t m = 0; m < masks.size(); ++m) {
    const Masks& mask = *masks[m];
    bool covered = mask[s][i] != 0;
    for (const Neighbour& n : near)
      covered = covered || (n.distance_m <= radius && mask[n.scan][n.pixel] != 0);
    bits |= covered ? 1u << m : 0u;
  }
  return bits;
}

// Counts for one merge (the in-model "merge" for coverage_before).
struct Tally {
  std::atomic<std::size_t> redundant_by_rule{0}, removed_by_rule{0};
  std::atomic<std::size_t> redundant_by_spacing{0}, removed_by_spacing{0};
  std::atomic<std::size_t> unique{0}, unique_removed{0};
  std::atomic<std::size_t> covered{0};
};

struct RowTally {
  std::size_t redundant_by_rule = 0, removed_by_rule = 0, redundant_by_spacing = 0,
              removed_by_spacing = 0, unique = 0, unique_removed = 0, covered = 0;
  void add_to(Tally& t) const {
    t.redundant_by_rule += redundant_by_rule;
    t.removed_by_rule += removed_by_rule;
    t.redundant_by_spacing += redundant_by_spacing;
    t.removed_by_spacing += removed_by_spacing;
    t.unique += unique;
    t.unique_removed += unique_removed;
    t.covered += covered;
  }
};

void tally_row(const Truth& t, std::span<const Masks* const> masks, std::size_t s, int row,
               double tie_tolerance, std::span<Tally> tallies, std::atomic<std::size_t>& samples) {
  const acquisition::Scan& scan = t.site.scans[s];
  const sim::ScanTruth& truth = t.site.truth[s];
  std::vector<RowTally> rows(masks.size());
  std::vector<Neighbour> near;
  std::size_t row_samples = 0;
  for (int col = 0; col < scan.columns; ++col) {
    const std::size_t i = scan.index(row, col);
    if (truth.object_id[i] == 0 || truth.mixed[i]) continue;
    if (t.prepared[s].in_model[i]) {
      const PointTruth p = point_truth(t, s, i, tie_tolerance);
      for (std::size_t m = 0; m < masks.size(); ++m) {
        const bool removed = (*masks[m])[s][i] == 0;
        RowTally& r = rows[m];
        r.redundant_by_rule += p.redundant_by_rule;
        r.removed_by_rule += p.redundant_by_rule && removed;
        r.redundant_by_spacing += p.redundant_by_spacing;
        r.removed_by_spacing += p.redundant_by_spacing && removed;
        r.unique += p.unique;
        r.unique_removed += p.unique && removed;
      }
    }
    if (row % 2 != 0 || col % 2 != 0) continue;
    ++row_samples;
    const unsigned bits = covered_by(t, masks, s, i, near);
    for (std::size_t m = 0; m < masks.size(); ++m) rows[m].covered += (bits >> m) & 1u;
  }
  for (std::size_t m = 0; m < masks.size(); ++m) rows[m].add_to(tallies[m]);
  samples += row_samples;
}

double share(std::size_t part, std::size_t whole) {
  return whole > 0 ? static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

// --- Merges ---

struct MergeRun {
  registration::MergeResult result;  // the fastest of the runs
  Masks keep;
};

MergeRun merge(std::span<const PreparedScan> prepared, std::span<const Eigen::Isometry3d> poses,
               const registration::MergeSettings& settings, int runs) {
  MergeRun best;
  for (int run = 0; run < runs; ++run) {
    registration::MergeResult r = registration::merge_by_sampling_rate(prepared, poses, settings);
    if (run == 0 || r.seconds < best.result.seconds) best.result = std::move(r);
  }
  for (const registration::MergeScanResult& scan : best.result.scans)
    best.keep.push_back(scan.keep);
  return best;
}

struct Registered {
  std::vector<Eigen::Isometry3d> T_world_scan;
  double max_rotation_error_deg = 0.0;
  double max_translation_error_m = 0.0;
  bool converged = false;
  double seconds = 0.0;
};

// Our registration (features, ICP, global refinement) from the true poses
// perturbed as trial 0 of bench "registration".
Registered register_perturbed(const SimulatedSite& site, std::span<const PreparedScan> prepared) {
  sim::Random random(sim::hash_combine(0x5245u, 0u));
  std::vector<Eigen::Isometry3d> initial = site.true_poses;
  for (std::size_t k = 1; k < initial.size(); ++k) {
    initial[k] =
        initial[k] * sim::random_pose_error(kMaxRotationErrorDeg, kMaxTranslationErrorM, random);
  }
  registration::RegistrationSettings settings;
  settings.features.hypotheses.seed = 1;
  const registration::RegistrationResult result =
      registration::register_scans(prepared, initial, settings);
  Registered out{result.T_world_scan, 0.0, 0.0, result.converged, result.seconds};
  for (std::size_t k = 1; k < initial.size(); ++k) {
    const auto [rotation, translation] =
        registration::pose_change(site.true_poses[k], result.T_world_scan[k]);
    out.max_rotation_error_deg =
        std::max(out.max_rotation_error_deg, rotation * 180.0 / std::numbers::pi);
    out.max_translation_error_m = std::max(out.max_translation_error_m, translation);
  }
  return out;
}

nlohmann::json merge_json(const MergeRun& run, const Tally& tally, const Tally& before,
                          std::size_t samples, double prepare_seconds) {
  std::size_t kept_points = 0;
  for (const auto& scan : run.result.scans) kept_points += scan.kept;
  const double coverage_before = share(before.covered, samples);
  const double coverage_after = share(tally.covered, samples);
  const registration::MergeResult& r = run.result;
  return {{"redundant_removed_share", share(tally.removed_by_rule, tally.redundant_by_rule)},
          {"redundant_removed_share_by_spacing",
           share(tally.removed_by_spacing, tally.redundant_by_spacing)},
          {"unique_removed_share", share(tally.unique_removed, tally.unique)},
          {"coverage_before", coverage_before},
          {"coverage_after", coverage_after},
          {"coverage_drop", coverage_before - coverage_after},
          {"coverage_samples", samples},
          {"points_per_second", r.seconds > 0.0 ? static_cast<double>(r.points) / r.seconds : 0.0},
          {"points", r.points},
          {"kept_points", kept_points},
          {"truth_redundant_points", tally.redundant_by_rule.load()},
          {"truth_redundant_points_by_spacing", tally.redundant_by_spacing.load()},
          {"truth_unique_points", tally.unique.load()},
          {"seconds", r.seconds},
          {"prepare_seconds", prepare_seconds}};
}

// Issue #5's goals, on the measures above.
nlohmann::json goals_json(const nlohmann::json& merge) {
  return {{"redundant_removed_share_at_least_0_9",
           merge["redundant_removed_share"].get<double>() >= 0.9},
          {"redundant_removed_share_by_spacing_at_least_0_9",
           merge["redundant_removed_share_by_spacing"].get<double>() >= 0.9},
          {"coverage_drop_at_most_0_005", merge["coverage_drop"].get<double>() <= 0.005},
          {"points_per_second_at_least_20m", merge["points_per_second"].get<double>() >= 20e6}};
}

}  // namespace

nlohmann::json run_merge_bench(const BenchOptions& options) {
  sim::ScannerModel model;
  if (options.smoke) {
    model.columns = 900;
    model.rows = 225;
  }
  const int scan_count = options.smoke ? 2 : 4;
  const SimulatedSite site = simulate_site("campus", model, scan_count);
  const auto prepare_start = std::chrono::steady_clock::now();
  std::vector<PreparedScan> prepared;
  for (std::size_t k = 0; k < site.scans.size(); ++k)
    prepared.push_back(registration::prepare_scan(site.scans[k], site.geometry[k], 0));
  const double prepare_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - prepare_start).count();

  const registration::MergeSettings settings;
  const int runs = options.smoke ? 1 : 3;
  const MergeRun at_truth = merge(prepared, site.true_poses, settings, runs);
  const Registered registered = register_perturbed(site, prepared);
  const MergeRun at_registered = merge(prepared, registered.T_world_scan, settings, runs);

  const Truth truth = make_truth(site, prepared);
  Masks in_model;
  for (const PreparedScan& scan : prepared) in_model.push_back(scan.in_model);
  const std::vector<const Masks*> masks = {&in_model, &at_truth.keep, &at_registered.keep};
  std::vector<Tally> tallies(masks.size());
  std::atomic<std::size_t> samples{0};
  for (std::size_t s = 0; s < site.scans.size(); ++s) {
    core::parallel_for_index(site.scans[s].rows, 0, [&](int row) {
      tally_row(truth, masks, s, row, settings.tie_tolerance, tallies, samples);
    });
  }

  nlohmann::json ours = merge_json(at_truth, tallies[1], tallies[0], samples, prepare_seconds);
  nlohmann::json ours_registered =
      merge_json(at_registered, tallies[2], tallies[0], samples, prepare_seconds);
  ours_registered["registration"] = {
      {"max_rotation_error_deg", registered.max_rotation_error_deg},
      {"max_translation_error_m", registered.max_translation_error_m},
      {"converged", registered.converged},
      {"seconds", registered.seconds},
      {"max_initial_error",
       {{"rotation_deg", kMaxRotationErrorDeg}, {"translation_m", kMaxTranslationErrorM}}}};
  return {{"suite", "merge"},
          {"site", "campus"},
          {"scans", scan_count},
          {"columns", model.columns},
          {"rows", model.rows},
          {"threads", core::worker_count(settings.threads)},
          {"ours", ours},
          {"ours_registered", ours_registered},
          {"goals", goals_json(ours)},
          {"goals_registered", goals_json(ours_registered)}};
}

}  // namespace scanbench::bench

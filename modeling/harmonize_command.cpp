#include "modeling/harmonize_command.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <map>

#include "acquisition/color_space.hpp"
#include "core/errors.hpp"
#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/scan_overlaps.hpp"

namespace scanbench::modeling {

double mean_pair_delta_e(std::span<const registration::ColorPair> pairs,
                         std::span<const store::ScanColorCorrection> corrections) {
  if (pairs.empty()) return 0.0;
  assert((corrections.empty() || std::all_of(pairs.begin(), pairs.end(),
                                             [&](const auto& p) {
                                               return std::max(p.scan_a, p.scan_b) <
                                                      corrections.size();
                                             })) &&
         "a correction for every scan of the pairs");
  const auto lab = [&](std::uint32_t scan, const Eigen::Vector3f& rgb) {
    Eigen::Vector3d linear = rgb.cast<double>();
    if (!corrections.empty()) {
      linear = corrections[scan].apply(linear).cwiseMax(0.0);
    }
    return acquisition::linear_rgb_to_lab(linear);
  };
  double sum = 0.0;
  for (const registration::ColorPair& p : pairs)
    sum += acquisition::delta_e(lab(p.scan_a, p.rgb_a), lab(p.scan_b, p.rgb_b));
  return sum / static_cast<double>(pairs.size());
}

namespace {

// The stage's result from the solver's: each scan's new correction (the
// stored one kept for scans in no pair), its reference, and ΔE before and
// after over all pairs and over each scan's own.
HarmonizeCommandResult harmonize_outcome(
    std::span<const store::StoredScanSummary> scans, std::span<const registration::ColorPair> pairs,
    const registration::HarmonizeResult& solved,
    const std::map<std::int64_t, store::ScanColorCorrection>& stored) {
  HarmonizeCommandResult out;
  out.pairs = pairs.size();
  out.iterations = solved.iterations;
  out.converged = solved.converged;
  std::vector<store::ScanColorCorrection> corrections;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    HarmonizeCommandScan scan;
    scan.id = scans[k].id;
    scan.name = scans[k].summary.name;
    if (solved.reference[k] >= 0) {
      scan.reference = scans[static_cast<std::size_t>(solved.reference[k])].id;
      scan.correction = solved.corrections[k];
    } else if (const auto kept = stored.find(scan.id); kept != stored.end()) {
      scan.correction = kept->second;
    }
    corrections.push_back(scan.correction);
    out.scans.push_back(std::move(scan));
  }
  out.delta_e_before = mean_pair_delta_e(pairs, {});
  out.delta_e_after = mean_pair_delta_e(pairs, corrections);
  for (std::size_t k = 0; k < out.scans.size(); ++k) {
    std::vector<registration::ColorPair> own;
    for (const registration::ColorPair& p : pairs)
      if (p.scan_a == k || p.scan_b == k) own.push_back(p);
    out.scans[k].pairs = own.size();
    out.scans[k].delta_e_before = mean_pair_delta_e(own, {});
    out.scans[k].delta_e_after = mean_pair_delta_e(own, corrections);
  }
  return out;
}

// The colour pairs of every two scans with colour whose bounds meet, in the
// order find_color_pairs gives them (by the pair's first scan, then its
// second), taking scan b and then each earlier scan a it pairs with from
// the cache: scans are loaded a few at a time.
std::vector<registration::ColorPair> streamed_color_pairs(
    const store::Project& project, std::span<const store::StoredScanSummary> scans,
    const registration::ColorPairSettings& settings, std::uint64_t memory_limit,
    core::Progress& progress) {
  std::vector<ScanPair> pairs = overlapping_pairs(scans);
  std::erase_if(pairs, [&scans](const ScanPair& p) {
    return !scans[static_cast<std::size_t>(p.first)].summary.has_color ||
           !scans[static_cast<std::size_t>(p.second)].summary.has_color;
  });
  std::vector<std::int64_t> plan;
  for (const int k : pair_pass_order(pairs, static_cast<int>(scans.size()), false))
    plan.push_back(scans[static_cast<std::size_t>(k)].id);
  // One scan kept in memory beyond the pair in hand, the others parked in
  // a temporary file until the plan brings them back. Whole scans: one
  // more kept would be as many megabytes as loading the next scan from the
  // project takes on top (16 path stations: 0.77 GB against 0.61 GB, in
  // the same time).
  ScanCache cache(project, memory_limit, settings.threads, "harmonize", progress,
                  {.form = ScanForm::kWhole, .spill = true, .max_kept = 1});
  cache.plan(plan);
  // The pairs each scan may take part in, shared among the scans it may
  // overlap: the solve grows with the scans, not with their overlaps.
  std::vector<std::size_t> partners(scans.size(), 0);
  for (const ScanPair& pair : pairs) {
    ++partners[static_cast<std::size_t>(pair.first)];
    ++partners[static_cast<std::size_t>(pair.second)];
  }
  std::map<std::pair<int, int>, std::vector<registration::ColorPair>> found;
  std::shared_ptr<const LoadedScan> b;
  for (const ScanPair& pair : pairs) {
    if (b == nullptr || b->id != scans[static_cast<std::size_t>(pair.second)].id) {
      b.reset();
      b = cache.get(scans[static_cast<std::size_t>(pair.second)].id);
      progress.update({"harmonize", static_cast<std::size_t>(pair.second) + 1, scans.size(),
                       "colour pairs of " + b->scan.name});
    }
    const std::shared_ptr<const LoadedScan> a =
        cache.get(scans[static_cast<std::size_t>(pair.first)].id);
    registration::ColorPairSettings link = settings;
    link.max_pairs_per_overlap =
        registration::link_pair_budget(settings, partners[static_cast<std::size_t>(pair.first)],
                                       partners[static_cast<std::size_t>(pair.second)]);
    found[{pair.first, pair.second}] = registration::color_pairs_between(
        a->prepared, b->prepared, static_cast<std::uint32_t>(pair.first),
        static_cast<std::uint32_t>(pair.second), a->scan.T_world_scan, b->scan.T_world_scan, link);
  }
  std::vector<registration::ColorPair> out;
  for (const auto& [which, list] : found) out.insert(out.end(), list.begin(), list.end());
  return out;
}

}  // namespace

HarmonizeCommandResult harmonize_project(store::Project& project,
                                         const HarmonizeCommandSettings& settings,
                                         core::Progress& progress,
                                         std::optional<std::uint64_t> memory_limit) {
  constexpr const char* kStage = "harmonize";
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t revision = project.revision();
  const std::vector<store::StoredScanSummary> scans = scans_with_geometry(project);
  const std::vector<registration::ColorPair> pairs = streamed_color_pairs(
      project, scans, settings.pairs, memory_limit_or_default(memory_limit), progress);
  if (pairs.empty()) {
    throw core::InputError(project.path().string(), {},
                           "no two scans with colour overlap: nothing to harmonise");
  }
  progress.throw_if_cancelled(kStage);
  const double search_seconds = core::seconds_since(start);
  const auto solve_start = std::chrono::steady_clock::now();
  const registration::HarmonizeResult solved =
      registration::harmonize_colors(pairs, scans.size(), settings.solve);
  const double solve_seconds = core::seconds_since(solve_start);
  HarmonizeCommandResult out =
      harmonize_outcome(scans, pairs, solved, project.scan_color_corrections());
  out.seconds = core::seconds_since(start);
  out.pair_search_seconds = search_seconds;
  out.solve_seconds = solve_seconds;
  progress.throw_if_cancelled(kStage);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (const HarmonizeCommandScan& scan : out.scans)
    project.put_scan_color_correction(edit, scan.id, scan.correction);
  edit.commit(result_json(out));
  return out;
}

}  // namespace scanbench::modeling

#include "modeling/harmonize_command.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <map>

#include "acquisition/color_space.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"
#include "core/spill_shelf.hpp"
#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/scan_overlaps.hpp"

namespace scanbench::modeling {

namespace {

// ΔE of one pair, each colour under its scan's correction when given.
double pair_delta_e(const registration::ColorPair& p,
                    std::span<const store::ScanColorCorrection> corrections) {
  assert((corrections.empty() || std::max(p.scan_a, p.scan_b) < corrections.size()) &&
         "a correction for every scan of the pairs");
  const auto lab = [&](std::uint32_t scan, const Eigen::Vector3f& rgb) {
    Eigen::Vector3d linear = rgb.cast<double>();
    if (!corrections.empty()) {
      linear = corrections[scan].apply(linear).cwiseMax(0.0);
    }
    return acquisition::linear_rgb_to_lab(linear);
  };
  return acquisition::delta_e(lab(p.scan_a, p.rgb_a), lab(p.scan_b, p.rgb_b));
}

}  // namespace

double mean_pair_delta_e(std::span<const registration::ColorPair> pairs,
                         std::span<const store::ScanColorCorrection> corrections) {
  if (pairs.empty()) return 0.0;
  double sum = 0.0;
  for (const registration::ColorPair& p : pairs) sum += pair_delta_e(p, corrections);
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
  // Sums of ΔE over all pairs and over each scan's, in the pairs' order.
  struct Sums {
    std::size_t pairs = 0;
    double before = 0.0;
    double after = 0.0;
  };
  Sums all;
  std::vector<Sums> own(out.scans.size());
  for (const registration::ColorPair& p : pairs) {
    const double before = pair_delta_e(p, {});
    const double after = pair_delta_e(p, corrections);
    for (Sums* sums : {&all, &own[p.scan_a], &own[p.scan_b]}) {
      ++sums->pairs;
      sums->before += before;
      sums->after += after;
    }
  }
  const auto mean = [](double sum, std::size_t count) {
    return count == 0 ? 0.0 : sum / static_cast<double>(count);
  };
  out.delta_e_before = mean(all.before, all.pairs);
  out.delta_e_after = mean(all.after, all.pairs);
  for (std::size_t k = 0; k < out.scans.size(); ++k) {
    out.scans[k].pairs = own[k].pairs;
    out.scans[k].delta_e_before = mean(own[k].before, own[k].pairs);
    out.scans[k].delta_e_after = mean(own[k].after, own[k].pairs);
  }
  return out;
}

// The colour pairs of every two scans with colour whose bounds meet, in the
// order find_color_pairs gives them (by the pair's first scan, then its
// second). One pass over the scans in the project's order, each loaded once:
// scan b is paired with the samples of every earlier scan a it may overlap,
// then its own samples are parked until its last pair as a first scan. In
// memory at once: one scan, and the samples of one or two, but where the
// temporary file cannot take them: then the waiting samples too, within
// the memory limit (core::MemoryShortage beyond it).
std::vector<registration::ColorPair> streamed_color_pairs(
    const store::Project& project, std::span<const store::StoredScanSummary> scans,
    const registration::ColorPairSettings& settings, std::uint64_t memory_limit,
    core::Progress& progress) {
  std::vector<ScanPair> pairs = overlapping_pairs(scans);
  std::erase_if(pairs, [&scans](const ScanPair& p) {
    return !scans[static_cast<std::size_t>(p.first)].summary.has_color ||
           !scans[static_cast<std::size_t>(p.second)].summary.has_color;
  });
  // The pairs each scan may take part in, shared among the scans it may
  // overlap: the solve grows with the scans, not with their overlaps. And
  // each scan's last pair as a first scan, after which its samples go.
  std::vector<std::size_t> partners(scans.size(), 0);
  std::vector<int> last_second(scans.size(), -1);
  for (const ScanPair& pair : pairs) {
    ++partners[static_cast<std::size_t>(pair.first)];
    ++partners[static_cast<std::size_t>(pair.second)];
    int& last = last_second[static_cast<std::size_t>(pair.first)];
    last = std::max(last, pair.second);
  }
  std::vector<int> visit;
  std::vector<std::int64_t> plan;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    if (partners[k] == 0) continue;
    visit.push_back(static_cast<int>(k));
    plan.push_back(scans[k].id);
  }
  ScanCache cache(project, memory_limit, settings.threads, "harmonize", progress,
                  {.form = ScanForm::kWhole, .spill = false, .max_kept = 0});
  cache.plan(plan);
  // The colour samples of the scans still to be paired as a pair's first
  // scan wait in a temporary file, or in memory where it cannot take them.
  core::SpillShelf<registration::ColorSamples> samples(scans.size(), 0);
  std::map<std::pair<int, int>, std::vector<registration::ColorPair>> found;
  auto next_pair = pairs.begin();  // ordered by second, then first
  for (std::size_t v = 0; v < visit.size(); ++v) {
    const int k = visit[v];
    const auto& summary = scans[static_cast<std::size_t>(k)];
    const std::shared_ptr<const LoadedScan> b = cache.get(summary.id);
    progress.update({"harmonize", v + 1, visit.size(), "colour pairs of " + summary.summary.name});
    for (; next_pair != pairs.end() && next_pair->second == k; ++next_pair) {
      const int a = next_pair->first;
      const auto& summary_a = scans[static_cast<std::size_t>(a)];
      registration::ColorPairSettings link = settings;
      link.max_pairs_per_overlap = registration::link_pair_budget(
          settings, partners[static_cast<std::size_t>(a)], partners[static_cast<std::size_t>(k)]);
      found[{a, k}] = registration::color_pairs_between(
          *samples.get(static_cast<std::size_t>(a)), b->prepared, static_cast<std::uint32_t>(a),
          static_cast<std::uint32_t>(k), summary_a.summary.T_world_scan,
          summary.summary.T_world_scan, link);
      if (last_second[static_cast<std::size_t>(a)] == k)
        samples.release(static_cast<std::size_t>(a));
      progress.throw_if_cancelled("harmonize");
    }
    if (last_second[static_cast<std::size_t>(k)] > k) {
      samples.put(static_cast<std::size_t>(k), registration::color_samples(b->prepared, settings));
      core::check_memory_limit(samples.bytes_in_memory() + b->bytes, memory_limit,
                               project.path().string(), "harmonize",
                               "scan " + std::to_string(summary.id) +
                                   " and the colour samples that a temporary file could not take "
                                   "(none could be made, or the disk is full)");
    }
  }
  std::vector<registration::ColorPair> out;
  for (auto& [which, list] : found) {
    out.insert(out.end(), list.begin(), list.end());
    list = {};
  }
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

#include "modeling/harmonize_command.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <map>

#include "acquisition/color_space.hpp"
#include "core/errors.hpp"
#include "modeling/command_json.hpp"
#include "modeling/loaded_scans.hpp"

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
    const LoadedScans& loaded, std::span<const registration::ColorPair> pairs,
    const registration::HarmonizeResult& solved,
    const std::map<std::int64_t, store::ScanColorCorrection>& stored) {
  HarmonizeCommandResult out;
  out.pairs = pairs.size();
  out.iterations = solved.iterations;
  out.converged = solved.converged;
  std::vector<store::ScanColorCorrection> corrections;
  for (std::size_t k = 0; k < loaded.ids.size(); ++k) {
    HarmonizeCommandScan scan;
    scan.id = loaded.ids[k];
    scan.name = loaded.scans[k].name;
    if (solved.reference[k] >= 0) {
      scan.reference = loaded.ids[static_cast<std::size_t>(solved.reference[k])];
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

}  // namespace

HarmonizeCommandResult harmonize_project(store::Project& project,
                                         const HarmonizeCommandSettings& settings,
                                         core::Progress& progress) {
  constexpr const char* kStage = "harmonize";
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t revision = project.revision();
  const LoadedScans loaded = load_scans(project, settings.pairs.threads, kStage, progress);
  std::vector<Eigen::Isometry3d> poses;
  for (const acquisition::Scan& scan : loaded.scans) poses.push_back(scan.T_world_scan);
  const std::vector<registration::ColorPair> pairs =
      registration::find_color_pairs(loaded.prepared, poses, settings.pairs);
  if (pairs.empty()) {
    throw core::InputError(project.path().string(), {},
                           "no two scans with colour overlap: nothing to harmonise");
  }
  progress.throw_if_cancelled(kStage);
  const registration::HarmonizeResult solved =
      registration::harmonize_colors(pairs, loaded.scans.size(), settings.solve);
  HarmonizeCommandResult out =
      harmonize_outcome(loaded, pairs, solved, project.scan_color_corrections());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.throw_if_cancelled(kStage);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (const HarmonizeCommandScan& scan : out.scans)
    project.put_scan_color_correction(edit, scan.id, scan.correction);
  edit.commit(result_json(out));
  return out;
}

}  // namespace scanbench::modeling

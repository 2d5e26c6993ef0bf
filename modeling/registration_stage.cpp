#include "modeling/registration_stage.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <nlohmann/json.hpp>

#include "acquisition/color_space.hpp"
#include "core/errors.hpp"
#include "modeling/scan_layers.hpp"
#include "modeling/segment_commands.hpp"
#include "modeling/settings_json.hpp"

namespace scanbench::modeling {
namespace {

// Scans with their geometry, in id order, and the prepared views of both.
struct LoadedScans {
  std::vector<std::int64_t> ids;
  std::vector<acquisition::Scan> scans;
  std::vector<acquisition::ScanGeometry> geometry;
  std::vector<registration::PreparedScan> prepared;
};

LoadedScans load_scans(const Project& project, int threads, const char* stage,
                       core::Progress& progress) {
  LoadedScans loaded;
  const std::vector<StoredScanSummary> scans = project.scans();
  if (scans.empty())
    throw core::InputError(project.path().string(), {}, "the project has no scans");
  for (const StoredScanSummary& stored : scans) {
    progress.throw_if_cancelled(stage);
    std::optional<acquisition::ScanGeometry> geometry = load_geometry(project, stored.id);
    if (!geometry) {
      throw core::InputError(project.path().string(), {},
                             "scan " + std::to_string(stored.id) + " (" + stored.summary.name +
                                 ") has no geometry: run scanbench geometry first");
    }
    loaded.ids.push_back(stored.id);
    loaded.scans.push_back(project.load_scan(stored.id));
    loaded.geometry.push_back(std::move(*geometry));
    progress.update({stage, loaded.ids.size(), scans.size(), "loaded " + stored.summary.name});
  }
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    loaded.prepared.push_back(
        registration::prepare_scan(loaded.scans[k], loaded.geometry[k], threads));
  }
  return loaded;
}

int index_of(const std::vector<std::int64_t>& ids, std::int64_t id, const std::string& file) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] == id) return static_cast<int>(k);
  }
  throw core::InputError(
      file, {}, "picked pairs name scan " + std::to_string(id) + ", which is not in the project");
}

// Turns picks by id into picks by position, and checks that every scan but
// the first has one, with an earlier scan as target.
std::vector<registration::PickedPairs> picks_by_index(const RegisterStageSettings& settings,
                                                      const std::vector<std::int64_t>& ids,
                                                      const std::string& file) {
  std::vector<registration::PickedPairs> picks;
  for (const ProjectPicks& p : settings.picks) {
    const int source = index_of(ids, p.source_id, file);
    const int target = index_of(ids, p.target_id, file);
    if (target >= source) {
      throw core::InputError(
          file, {},
          "picked pairs of scan " + std::to_string(p.source_id) + " must target an earlier scan");
    }
    picks.push_back({source, target, p.pairs});
  }
  for (int k = 1; k < static_cast<int>(ids.size()); ++k) {
    const bool found =
        std::any_of(picks.begin(), picks.end(),
                    [k](const registration::PickedPairs& p) { return p.source == k; });
    if (!found) {
      throw core::InputError(
          file, {}, "no picked pairs for scan " + std::to_string(ids[static_cast<std::size_t>(k)]));
    }
  }
  return picks;
}

nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  }
  return rows;
}

nlohmann::json pair_json(const registration::PairReport& p, const std::vector<std::int64_t>& ids) {
  const auto id = [&ids](int k) { return ids[static_cast<std::size_t>(k)]; };
  return {{"source", id(p.source)},
          {"target", id(p.target)},
          {"registered", p.registered},
          {"failure", p.failure},
          {"start", registration::icp_start_name(p.start)},
          {"coarse",
           {{"method", registration::coarse_method_name(p.coarse.method)},
            {"success", p.coarse.success},
            {"inlier_ratio", p.coarse.inlier_ratio},
            {"overlap", p.coarse.overlap},
            {"free_space_violation", p.coarse.free_space_violation},
            {"count", p.coarse.count},
            {"rms_m", p.coarse.rms_m},
            {"seconds", p.coarse.seconds},
            {"failure", p.coarse.failure}}},
          {"rms_m", p.icp.rms_m},
          {"overlap", p.icp.overlap},
          {"free_space_violation", p.icp.free_space_violation},
          {"inliers", p.icp.correspondences},
          {"iterations", p.icp.iterations},
          {"converged", p.icp.converged},
          {"seconds", p.seconds}};
}

std::string report_json(const registration::RegistrationResult& r,
                        const std::vector<std::int64_t>& ids,
                        const std::vector<acquisition::Scan>& scans) {
  nlohmann::json report;
  report["pairs"] = nlohmann::json::array();
  for (const auto& pair : r.pairs) report["pairs"].push_back(pair_json(pair, ids));
  report["global"] = {{"rounds", r.global.rounds},
                      {"converged", r.global.converged},
                      {"inliers", r.global.correspondences},
                      {"seconds", r.global.seconds}};
  report["edges"] = nlohmann::json::array();
  for (const auto& e : r.edges) {
    report["edges"].push_back({{"source", ids[static_cast<std::size_t>(e.source)]},
                               {"target", ids[static_cast<std::size_t>(e.target)]},
                               {"rms_m", e.quality.rms_m},
                               {"overlap", e.quality.overlap},
                               {"free_space_violation", e.quality.free_space_violation},
                               {"inliers", e.quality.correspondences}});
  }
  report["overall"] = {
      {"rms_m", r.rms_m},           {"overlap", r.overlap},     {"inliers", r.correspondences},
      {"iterations", r.iterations}, {"converged", r.converged}, {"seconds", r.seconds}};
  report["poses"] = nlohmann::json::array();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    report["poses"].push_back({{"scan", ids[k]},
                               {"name", scans[k].name},
                               {"initial_T_world_scan", pose_json(scans[k].T_world_scan)},
                               {"T_world_scan", pose_json(r.T_world_scan[k])}});
  }
  return report.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

RegisterStageResult register_project(Project& project, const RegisterStageSettings& settings,
                                     core::Progress& progress) {
  constexpr const char* kStage = "register";
  const std::int64_t revision = project.revision();
  LoadedScans loaded = load_scans(project, settings.registration.icp.threads, kStage, progress);
  registration::RegistrationSettings run = settings.registration;
  if (run.coarse == registration::CoarseMethod::kPointPairs) {
    run.picks = picks_by_index(settings, loaded.ids, project.path().string());
  }
  std::vector<Eigen::Isometry3d> initial;
  for (const acquisition::Scan& scan : loaded.scans) initial.push_back(scan.T_world_scan);
  RegisterStageResult out;
  out.ids = loaded.ids;
  out.result = registration::register_scans(loaded.prepared, initial, run, &progress);
  out.report_json = report_json(out.result, loaded.ids, loaded.scans);
  progress.throw_if_cancelled(kStage);
  std::map<std::int64_t, Eigen::Isometry3d> moved;
  for (std::size_t k = 0; k < loaded.ids.size(); ++k)
    moved.emplace(loaded.ids[k], out.result.T_world_scan[k]);
  const std::vector<ObjectNode> refigured = node_figures_after_moving(project, moved);

  Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (const ObjectNode& node : refigured) project.put_node(edit, node);
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    out.names.push_back(loaded.scans[k].name);
    loaded.scans[k].T_world_scan = out.result.T_world_scan[k];
    project.set_pose(edit, loaded.ids[k], loaded.scans[k]);
    project.remove_layer(edit, loaded.ids[k], layer::kKeep);
  }
  edit.commit(out.report_json);
  return out;
}

MergeStageResult merge_project(Project& project, const registration::MergeSettings& settings,
                               core::Progress& progress) {
  constexpr const char* kStage = "merge";
  const std::int64_t revision = project.revision();
  const LoadedScans loaded = load_scans(project, settings.threads, kStage, progress);
  std::vector<Eigen::Isometry3d> poses;
  for (const acquisition::Scan& scan : loaded.scans) poses.push_back(scan.T_world_scan);
  registration::MergeResult merged =
      registration::merge_by_sampling_rate(loaded.prepared, poses, settings);
  MergeStageResult out;
  out.points = merged.points;
  out.seconds = merged.seconds;
  std::vector<EncodedLayer> masks;
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    masks.push_back(
        encode_layer<std::uint8_t>(layer::kKeep, ElementType::kU8, merged.scans[k].keep));
    MergeStageScan scan{loaded.ids[k], loaded.scans[k].name, std::move(merged.scans[k])};
    scan.counts.keep.clear();
    out.scans.push_back(std::move(scan));
  }
  progress.throw_if_cancelled(kStage);

  Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (std::size_t k = 0; k < loaded.ids.size(); ++k)
    project.put_layer(edit, loaded.ids[k], masks[k]);
  edit.commit(merge_result_json(out));
  return out;
}

std::string merge_result_json(const MergeStageResult& out) {
  std::size_t kept = 0;
  nlohmann::json scans = nlohmann::json::array();
  for (const MergeStageScan& s : out.scans) {
    kept += s.counts.kept;
    scans.push_back({{"id", s.id},
                     {"name", s.name},
                     {"in_model", s.counts.in_model},
                     {"kept", s.counts.kept},
                     {"redundant", s.counts.redundant}});
  }
  return nlohmann::json{
      {"scans", scans}, {"points", out.points}, {"kept", kept}, {"seconds", out.seconds}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

double mean_pair_delta_e(std::span<const registration::ColorPair> pairs,
                         std::span<const ScanColorCorrection> corrections) {
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
HarmonizeStageResult harmonize_outcome(const LoadedScans& loaded,
                                       std::span<const registration::ColorPair> pairs,
                                       const registration::HarmonizeResult& solved,
                                       const std::map<std::int64_t, ScanColorCorrection>& stored) {
  HarmonizeStageResult out;
  out.pairs = pairs.size();
  out.iterations = solved.iterations;
  out.converged = solved.converged;
  std::vector<ScanColorCorrection> corrections;
  for (std::size_t k = 0; k < loaded.ids.size(); ++k) {
    HarmonizeStageScan scan;
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

std::string harmonize_settings_json(const HarmonizeStageSettings& settings) {
  return nlohmann::json{{"model", registration::color_model_name(settings.solve.model)},
                        {"loss_scale", settings.solve.loss_scale},
                        {"stride", settings.pairs.stride},
                        {"max_distance_m", settings.pairs.max_distance_m},
                        {"max_normal_angle_deg", settings.pairs.max_normal_angle_deg},
                        {"max_local_step", settings.pairs.max_local_step},
                        {"max_pairs_per_overlap", settings.pairs.max_pairs_per_overlap}}
      .dump();
}

}  // namespace

HarmonizeStageResult harmonize_project(Project& project, const HarmonizeStageSettings& settings,
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
  HarmonizeStageResult out =
      harmonize_outcome(loaded, pairs, solved, project.scan_color_corrections());
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  progress.throw_if_cancelled(kStage);

  Project::Edit edit = project.begin_command(kStage, harmonize_settings_json(settings), revision);
  out.command_id = edit.command_id();
  for (const HarmonizeStageScan& scan : out.scans)
    project.put_scan_color_correction(edit, scan.id, scan.correction);
  edit.commit(harmonize_result_json(out));
  return out;
}

std::string harmonize_result_json(const HarmonizeStageResult& out) {
  nlohmann::json scans = nlohmann::json::array();
  for (const HarmonizeStageScan& s : out.scans) {
    nlohmann::json matrix = nlohmann::json::array();
    for (int r = 0; r < 3; ++r)
      matrix.push_back(
          {s.correction.matrix(r, 0), s.correction.matrix(r, 1), s.correction.matrix(r, 2)});
    scans.push_back(
        {{"id", s.id},
         {"name", s.name},
         {"reference", s.reference ? nlohmann::json(*s.reference) : nlohmann::json()},
         {"pairs", s.pairs},
         {"delta_e_before", s.delta_e_before},
         {"delta_e_after", s.delta_e_after},
         {"matrix", matrix},
         {"offset", {s.correction.offset.x(), s.correction.offset.y(), s.correction.offset.z()}}});
  }
  return nlohmann::json{{"scans", scans},
                        {"pairs", out.pairs},
                        {"delta_e_before", out.delta_e_before},
                        {"delta_e_after", out.delta_e_after},
                        {"iterations", out.iterations},
                        {"converged", out.converged},
                        {"seconds", out.seconds}}
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace scanbench::modeling

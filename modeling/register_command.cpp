#include "modeling/register_command.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "modeling/loaded_scans.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/settings_json.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

int index_of(const std::vector<std::int64_t>& ids, std::int64_t id, const std::string& file) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] == id) return static_cast<int>(k);
  }
  throw core::InputError(
      file, {}, "picked pairs name scan " + std::to_string(id) + ", which is not in the project");
}

// Turns picks by id into picks by position, and checks that every scan but
// the first has one, with an earlier scan as target.
std::vector<registration::PickedPairs> picks_by_index(const RegisterCommandSettings& settings,
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

RegisterCommandResult register_project(store::Project& project,
                                       const RegisterCommandSettings& settings,
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
  RegisterCommandResult out;
  out.ids = loaded.ids;
  out.result = registration::register_scans(loaded.prepared, initial, run, &progress);
  out.report_json = report_json(out.result, loaded.ids, loaded.scans);
  progress.throw_if_cancelled(kStage);
  std::map<std::int64_t, Eigen::Isometry3d> moved;
  for (std::size_t k = 0; k < loaded.ids.size(); ++k)
    moved.emplace(loaded.ids[k], out.result.T_world_scan[k]);
  const std::vector<store::ObjectNode> refigured = node_figures_after_moving(project, moved);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (const store::ObjectNode& node : refigured) project.put_node(edit, node);
  for (std::size_t k = 0; k < loaded.scans.size(); ++k) {
    out.names.push_back(loaded.scans[k].name);
    loaded.scans[k].T_world_scan = out.result.T_world_scan[k];
    project.set_pose(edit, loaded.ids[k], loaded.scans[k]);
    project.remove_layer(edit, loaded.ids[k], store::layer::kKeep);
  }
  edit.commit(out.report_json);
  return out;
}

}  // namespace scanbench::modeling

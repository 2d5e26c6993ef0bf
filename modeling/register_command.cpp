#include "modeling/register_command.hpp"

#include <algorithm>
#include <map>
#include <string>

#include "core/errors.hpp"
#include "modeling/carried_objects.hpp"
#include "modeling/command_json.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/scan_cache.hpp"
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

// No pair registered: nothing is stored (the poses would be the ones the
// scans had), and the failure names each pair and why.
void refuse_when_nothing_registered(const store::Project& project,
                                    const RegisterCommandResult& out) {
  const std::vector<registration::PairReport>& pairs = out.result.pairs;
  if (pairs.empty() ||
      std::any_of(pairs.begin(), pairs.end(), [](const auto& pair) { return pair.registered; }))
    return;
  std::string why;
  for (const registration::PairReport& pair : pairs) {
    why += (why.empty() ? "" : "; ") + std::string("scan ") +
           std::to_string(out.ids[static_cast<std::size_t>(pair.source)]) + " to scan " +
           std::to_string(out.ids[static_cast<std::size_t>(pair.target)]) + ": " + pair.failure;
  }
  throw core::RuntimeFailure(project.path().string(), {},
                             "no pair of scans registered, nothing stored (" + why + ")");
}

// Every scan's world bounds at its new pose, from its ranges alone (one
// scan at a time, without its geometry or prepared view).
std::vector<std::optional<Eigen::AlignedBox3d>> world_bounds_at(
    const store::Project& project, const std::vector<std::int64_t>& ids,
    const std::vector<Eigen::Isometry3d>& poses, core::Progress& progress) {
  std::vector<std::optional<Eigen::AlignedBox3d>> bounds;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    progress.throw_if_cancelled("register");
    bounds.push_back(acquisition::world_bounds(
        project.load_scan(ids[k], {.intensity = false, .color = false}), poses[k]));
  }
  return bounds;
}

}  // namespace

RegisterCommandResult register_project(store::Project& project,
                                       const RegisterCommandSettings& settings,
                                       core::Progress& progress,
                                       std::optional<std::uint64_t> memory_limit) {
  constexpr const char* kStage = "register";
  const std::int64_t revision = project.revision();
  const std::vector<store::StoredScanSummary> scans = scans_with_geometry(project);
  RegisterCommandResult out;
  for (const store::StoredScanSummary& stored : scans) {
    out.ids.push_back(stored.id);
    out.names.push_back(stored.summary.name);
    out.initial_T_world_scan.push_back(stored.summary.T_world_scan);
  }
  registration::RegistrationSettings run = settings.registration;
  if (run.coarse == registration::CoarseMethod::kPointPairs) {
    run.picks = picks_by_index(settings, out.ids, project.path().string());
  }
  CachedScans stream(project, out.ids, memory_limit_or_default(memory_limit),
                     settings.registration.icp.threads, kStage, progress);
  out.result = registration::register_scans(stream, out.initial_T_world_scan, run, &progress);
  progress.throw_if_cancelled(kStage);
  refuse_when_nothing_registered(project, out);
  std::map<std::int64_t, Eigen::Isometry3d> moved;
  for (std::size_t k = 0; k < out.ids.size(); ++k)
    moved.emplace(out.ids[k], out.result.T_world_scan[k]);
  const CarriedAgain carried =
      carry_objects_again(project, scans, stream, out.result.T_world_scan, progress);
  out.object_points_released = carried.released;
  out.object_points_carried = carried.carried_points;
  const std::vector<store::ObjectNode> refigured =
      node_figures_after_moving(project, moved, carried.memberships);
  const std::vector<std::optional<Eigen::AlignedBox3d>> bounds =
      world_bounds_at(project, out.ids, out.result.T_world_scan, progress);
  progress.throw_if_cancelled(kStage);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (const store::ObjectNode& node : refigured) project.put_node(edit, node);
  for (const auto& [scan_id, membership] : carried.memberships) {
    put_membership(project, edit, scan_id, membership);
    project.put_layer(
        edit, scan_id,
        store::encode_layer<std::uint8_t>(store::layer::kCarried, store::ElementType::kU8,
                                          carried.carried.at(scan_id)));
  }
  for (std::size_t k = 0; k < out.ids.size(); ++k) {
    project.set_pose(edit, out.ids[k], out.result.T_world_scan[k], bounds[k]);
    project.remove_layer(edit, out.ids[k], store::layer::kKeep);
  }
  edit.commit(result_json(out));
  return out;
}

}  // namespace scanbench::modeling

// The results of command_json.hpp: what each command stores in the journal
// and prints with --json.
#include <nlohmann/json.hpp>

#include "modeling/command_json.hpp"
#include "modeling/geometry_command.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"

namespace scanbench::modeling {
namespace {

nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
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

nlohmann::json to_report(const ImportResult& r) {
  return {{"scans", r.scan_ids}};
}

nlohmann::json to_report(const GeometryCommandResult& result) {
  nlohmann::json scans = nlohmann::json::array();
  for (const GeometryCommandScan& s : result.scans) {
    scans.push_back({{"id", s.id},
                     {"valid_points", s.valid_points},
                     {"normals", s.normals},
                     {"recorded_normals", s.recorded_normals},
                     {"mixed_pixels", s.mixed_pixels},
                     {"edge_pixels", s.edge_pixels},
                     {"range_noise",
                      {{"noise_m", s.range_noise.noise_m},
                       {"noise_per_m", s.range_noise.noise_per_m},
                       {"noise_per_m2", s.range_noise.noise_per_m2}}},
                     {"noise_estimated", s.noise_estimated}});
  }
  return {{"scans", scans}, {"seconds", result.seconds}};
}

nlohmann::json to_report(const RegisterCommandResult& out) {
  const registration::RegistrationResult& r = out.result;
  const std::vector<std::int64_t>& ids = out.ids;
  nlohmann::json report;
  report["pairs"] = nlohmann::json::array();
  for (const auto& pair : r.pairs) report["pairs"].push_back(pair_json(pair, ids));
  report["global"] = {{"rounds", r.global.rounds},           {"converged", r.global.converged},
                      {"inliers", r.global.correspondences}, {"seconds", r.global.seconds},
                      {"patch_visits", r.patch_visits},      {"scan_visits", r.scan_visits}};
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
      {"iterations", r.iterations}, {"converged", r.converged}, {"seconds", r.seconds},
      {"pair_tests", r.pair_tests}};
  report["poses"] = nlohmann::json::array();
  for (std::size_t k = 0; k < ids.size(); ++k) {
    report["poses"].push_back({{"scan", ids[k]},
                               {"name", out.names[k]},
                               {"initial_T_world_scan", pose_json(out.initial_T_world_scan[k])},
                               {"T_world_scan", pose_json(r.T_world_scan[k])}});
  }
  report["objects"] = {{"points_released", out.object_points_released},
                       {"points_carried", out.object_points_carried}};
  return report;
}

nlohmann::json to_report(const MergeCommandResult& out) {
  std::size_t kept = 0;
  nlohmann::json scans = nlohmann::json::array();
  for (const MergeCommandScan& s : out.scans) {
    kept += s.counts.kept;
    scans.push_back({{"id", s.id},
                     {"name", s.name},
                     {"in_model", s.counts.in_model},
                     {"kept", s.counts.kept},
                     {"redundant", s.counts.redundant}});
  }
  return {{"scans", scans}, {"points", out.points}, {"kept", kept}, {"seconds", out.seconds}};
}

nlohmann::json to_report(const HarmonizeCommandResult& out) {
  nlohmann::json scans = nlohmann::json::array();
  for (const HarmonizeCommandScan& s : out.scans) {
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
  return {{"scans", scans},
          {"pairs", out.pairs},
          {"delta_e_before", out.delta_e_before},
          {"delta_e_after", out.delta_e_after},
          {"iterations", out.iterations},
          {"converged", out.converged},
          {"seconds", out.seconds},
          {"pair_search_seconds", out.pair_search_seconds},
          {"solve_seconds", out.solve_seconds}};
}

}  // namespace

template <typename Result>
std::string result_json(const Result& result) {
  return dump(to_report(result));
}

template std::string result_json<ImportResult>(const ImportResult&);
template std::string result_json<GeometryCommandResult>(const GeometryCommandResult&);
template std::string result_json<RegisterCommandResult>(const RegisterCommandResult&);
template std::string result_json<MergeCommandResult>(const MergeCommandResult&);
template std::string result_json<HarmonizeCommandResult>(const HarmonizeCommandResult&);

}  // namespace scanbench::modeling

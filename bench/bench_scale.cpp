#include "bench/bench_scale.hpp"

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/child_process.hpp"
#include "bench/scratch_folder.hpp"
#include "modeling/store/project.hpp"
#include "registration/pose_parameters.hpp"

namespace scanbench::bench {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPoseErrorDeg = "3";
constexpr const char* kPoseErrorM = "0.5";

// A stage past this is stopped and reported as timed out [s].
constexpr double kStageTimeoutS = 1800.0;

// A stage run in its own process.
ChildRun run_stage(const std::string& stage, const std::vector<std::string>& arguments,
                   const fs::path& dir) {
  return run_scanbench(stage, arguments, dir, kStageTimeoutS);
}

// The same for a stage the campaign cannot do without: throws naming it
// and quoting its error when it fails.
ChildRun run_needed_stage(const std::string& stage, const std::vector<std::string>& arguments,
                          const fs::path& dir) {
  ChildRun run = run_stage(stage, arguments, dir);
  if (run.exit_code != 0) {
    throw std::runtime_error("bench scale: " + stage + " exited with " +
                             std::to_string(run.exit_code) + ": " + run.err);
  }
  return run;
}

// The scan files `scanbench simulate` listed ("  scan  PATH" lines).
std::vector<std::string> simulated_scans(const std::string& out) {
  std::vector<std::string> files;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    constexpr std::string_view kScan = "  scan  ";
    if (line.starts_with(kScan)) files.push_back(line.substr(kScan.size()));
  }
  return files;
}

// The true poses of truth.json (docs/simulation.md), in scan order.
std::vector<Eigen::Isometry3d> true_poses(const fs::path& truth_json) {
  std::ifstream in(truth_json);
  const nlohmann::json truth = nlohmann::json::parse(in);
  std::vector<Eigen::Isometry3d> poses;
  for (const nlohmann::json& scan : truth.at("scans")) {
    const auto m = scan.at("T_world_scan").get<std::array<double, 16>>();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) pose.matrix()(r, c) = m[static_cast<std::size_t>(4 * r + c)];
    }
    poses.push_back(pose);
  }
  return poses;
}

struct RegistrationErrors {
  double rotation_deg = 0.0;  // largest over the scans' poses
  double translation_m = 0.0;
  // Largest over the measured pairs (the report's edges): the error of the
  // registered relative pose. An open traverse's poses drift with its
  // length whatever the registration; its links show the registration's
  // own error.
  double link_rotation_deg = 0.0;
  double link_translation_m = 0.0;
};

// Registration errors against the truth, of every scan and of every edge of
// the register report.
RegistrationErrors registration_errors(const fs::path& project,
                                       const std::vector<Eigen::Isometry3d>& truth,
                                       const nlohmann::json& report) {
  const std::vector<store::StoredScanSummary> scans =
      store::Project::open_read_only(project).scans();
  RegistrationErrors errors;
  std::map<std::int64_t, std::size_t> position;
  for (std::size_t k = 0; k < scans.size() && k < truth.size(); ++k) {
    position[scans[k].id] = k;
    const auto [r, t] = registration::pose_change(truth[k], scans[k].summary.T_world_scan);
    errors.rotation_deg = std::max(errors.rotation_deg, r * 180.0 / std::numbers::pi);
    errors.translation_m = std::max(errors.translation_m, t);
  }
  if (!report.is_object() || !report.contains("edges")) return errors;
  for (const nlohmann::json& edge : report["edges"]) {
    const auto a = position.find(edge["source"].get<std::int64_t>());
    const auto b = position.find(edge["target"].get<std::int64_t>());
    if (a == position.end() || b == position.end()) continue;
    const Eigen::Isometry3d true_link = truth[b->second].inverse() * truth[a->second];
    const Eigen::Isometry3d link =
        scans[b->second].summary.T_world_scan.inverse() * scans[a->second].summary.T_world_scan;
    const auto [r, t] = registration::pose_change(true_link, link);
    errors.link_rotation_deg = std::max(errors.link_rotation_deg, r * 180.0 / std::numbers::pi);
    errors.link_translation_m = std::max(errors.link_translation_m, t);
  }
  return errors;
}

std::size_t campaign_points(const fs::path& project) {
  std::size_t points = 0;
  for (const store::StoredScanSummary& scan : store::Project::open_read_only(project).scans())
    points += scan.summary.valid_points;
  return points;
}

// A stage's figures; for a stage that failed, how (its error, or that it
// ran past kStageTimeoutS) instead of a throughput.
nlohmann::json stage_json(const ChildRun& run, std::size_t points) {
  if (run.exit_code != 0) {
    return {{"seconds", run.seconds},
            {"exit_code", run.exit_code},
            {"timed_out", run.timed_out},
            {"error", run.err.substr(0, 500)}};
  }
  return {{"seconds", run.seconds},
          {"points_per_second", static_cast<double>(points) / run.seconds},
          {"peak_rss_bytes", run.peak_rss_bytes}};
}

nlohmann::json run_campaign(int scans, const BenchOptions& options, const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path scan_dir = dir / "scans";
  const ChildRun simulated =
      run_needed_stage("simulate",
                       {"simulate", "--site", options.site, "--out", scan_dir.string(), "--scans",
                        std::to_string(scans), "--columns", std::to_string(options.columns),
                        "--rows", std::to_string(options.rows), "--pose-error-deg", kPoseErrorDeg,
                        "--pose-error-m", kPoseErrorM},
                       dir);
  const std::string project = (dir / "campaign.sbproj").string();
  std::vector<std::string> import{"import", project};
  for (const std::string& file : simulated_scans(simulated.out)) import.push_back(file);

  nlohmann::json stages = nlohmann::json::object();
  const ChildRun imported = run_needed_stage("import", import, dir);
  const std::size_t points = campaign_points(project);
  stages["import"] = stage_json(imported, points);
  stages["geometry"] = stage_json(run_stage("geometry", {"geometry", project}, dir), points);
  const ChildRun registered = run_stage("register", {"register", project, "--json"}, dir);
  stages["register"] = stage_json(registered, points);
  stages["merge"] = stage_json(run_stage("merge", {"merge", project}, dir), points);
  // One scan has no colour pairs: harmonize refuses it, and rightly.
  stages["harmonize"] =
      scans < 2 ? nlohmann::json()
                : stage_json(run_stage("harmonize", {"harmonize", project}, dir), points);
  const std::string las = (dir / "merged.las").string();
  stages["export_las"] = stage_json(
      run_stage("export_las", {"export", project, "--format", "las", "-o", las, "--merged"}, dir),
      points);

  const nlohmann::json report = nlohmann::json::parse(registered.out, nullptr, false);
  const RegistrationErrors errors =
      registration_errors(project, true_poses(scan_dir / "truth.json"), report);
  return {{"scans", scans},
          {"points", points},
          {"pair_tests", report.is_object() ? report["overall"]["pair_tests"] : nlohmann::json()},
          {"max_rotation_error_deg", errors.rotation_deg},
          {"max_translation_error_m", errors.translation_m},
          {"max_link_rotation_error_deg", errors.link_rotation_deg},
          {"max_link_translation_error_m", errors.link_translation_m},
          {"project_bytes", fs::file_size(project)},
          {"stages", stages}};
}

// Per stage, the largest campaign's figure over the 4-station one's.
nlohmann::json ratios(const nlohmann::json& campaigns, const char* field) {
  const nlohmann::json* four = nullptr;
  const nlohmann::json* largest_ptr = nullptr;
  for (const nlohmann::json& c : campaigns) {
    if (c["scans"] == 4) four = &c;
    if (largest_ptr == nullptr || c["scans"].get<int>() > (*largest_ptr)["scans"].get<int>())
      largest_ptr = &c;
  }
  if (largest_ptr == nullptr) return nlohmann::json::object();
  const nlohmann::json& largest = *largest_ptr;
  nlohmann::json out = nlohmann::json::object();
  if (four == nullptr || largest["scans"].get<int>() <= 4) return out;
  for (const auto& [stage, figures] : largest["stages"].items()) {
    const nlohmann::json& at_four = (*four)["stages"][stage];
    if (!figures.contains(field) || !at_four.contains(field)) continue;
    out[stage] = figures[field].get<double>() / (*four)["stages"][stage][field].get<double>();
  }
  return out;
}

}  // namespace

nlohmann::json run_scale_bench(const BenchOptions& requested) {
  BenchOptions options = requested;
  if (options.smoke) {
    options.sizes = {1, 2};
    options.columns = 720;
    options.rows = 180;
  }
  ScratchFolder scratch("scale");
  nlohmann::json campaigns = nlohmann::json::array();
  for (const int size : options.sizes) {
    campaigns.push_back(run_campaign(size, options, scratch.path() / std::to_string(size)));
    fs::remove_all(scratch.path() / std::to_string(size));
  }
  return {{"suite", "scale"},
          {"site", options.site},
          {"columns", options.columns},
          {"rows", options.rows},
          {"campaigns", campaigns},
          {"rss_ratio", ratios(campaigns, "peak_rss_bytes")},
          {"throughput_ratio", ratios(campaigns, "points_per_second")}};
}

}  // namespace scanbench::bench

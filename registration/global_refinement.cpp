// Joint point-to-plane refinement of all poses (a multi-view ICP in the
// spirit of Pulli 1999), solved in one Ceres problem per association round.
#include "registration/global_refinement.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <map>
#include <numbers>

#include "core/parallel.hpp"
#include "core/timing.hpp"
#include "registration/association.hpp"
#include "registration/point_to_plane_costs.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {
namespace {

// The correspondences of one edge, and the poses they tie together.
struct EdgeMatches {
  std::vector<PlaneCorrespondence> matches;
  PoseParameters* source = nullptr;
  PoseParameters* target = nullptr;
};

ceres::Solver::Options solver_options(const GlobalSettings& settings) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = settings.solver_iterations;
  options.num_threads = core::worker_count(settings.icp.threads);
  options.logging_type = ceres::SILENT;
  return options;
}

// One round: associate every edge at the current poses, then solve jointly.
// Edges are associated target by target (each target scan taken from the
// stream once), and enter the problem in their own order. Returns the
// number of correspondences used.
std::size_t solve_round(std::span<const SampleCloud> samples, ScanStream& scans,
                        std::span<const ScanEdge> edges, std::vector<PoseParameters>& poses,
                        double gate_m, const GlobalSettings& settings) {
  const double min_cos = std::cos(settings.icp.max_normal_angle_deg * std::numbers::pi / 180.0);
  std::vector<std::vector<PlaneCorrespondence>> matches(edges.size());
  for_each_target(scans, edges, [&](const PreparedScan& target, std::size_t e) {
    const auto a = static_cast<std::size_t>(edges[e].source);
    const auto b = static_cast<std::size_t>(edges[e].target);
    const Eigen::Isometry3d T_target_source = poses[b].isometry().inverse() * poses[a].isometry();
    matches[e] = plane_correspondences(samples[a], target,
                                       associate_samples(samples[a], target, T_target_source,
                                                         {gate_m, min_cos}, settings.icp.threads));
  });
  std::vector<EdgeMatches> associated;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (matches[e].size() < settings.icp.min_correspondences) continue;
    associated.push_back({std::move(matches[e]), &poses[static_cast<std::size_t>(edges[e].source)],
                          &poses[static_cast<std::size_t>(edges[e].target)]});
  }
  ceres::Problem problem;
  std::size_t total = 0;
  for (const EdgeMatches& edge : associated) {
    for (std::span<const PlaneCorrespondence> block : correspondence_blocks(edge.matches)) {
      problem.AddResidualBlock(new PairPointToPlaneCost(block, settings.icp.loss_scale_m), nullptr,
                               edge.source->rotation, edge.source->translation,
                               edge.target->rotation, edge.target->translation);
    }
    total += edge.matches.size();
  }
  for (PoseParameters& pose : poses) {
    if (!problem.HasParameterBlock(pose.rotation)) continue;
    problem.SetManifold(pose.rotation, new ceres::EigenQuaternionManifold);
  }
  if (problem.HasParameterBlock(poses[0].rotation)) {
    problem.SetParameterBlockConstant(poses[0].rotation);
    problem.SetParameterBlockConstant(poses[0].translation);
  }
  if (total == 0) return 0;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(settings), &problem, &summary);
  return total;
}

}  // namespace

void for_each_target(ScanStream& scans, std::span<const ScanEdge> edges,
                     const std::function<void(const PreparedScan&, std::size_t)>& visit) {
  std::map<int, std::vector<std::size_t>> by_target;
  for (std::size_t e = 0; e < edges.size(); ++e) by_target[edges[e].target].push_back(e);
  std::vector<int> order;
  for (const auto& [target, indices] : by_target) order.push_back(target);
  scans.plan(order);
  for (const auto& [target, indices] : by_target) {
    const std::shared_ptr<const PreparedScan> scan = scans.get(target);
    for (const std::size_t e : indices) visit(*scan, e);
  }
}

GlobalResult refine_globally(std::span<const SampleCloud> samples, ScanStream& scans,
                             std::vector<Eigen::Isometry3d> T_first_scan,
                             std::span<const ScanEdge> edges, const GlobalSettings& settings) {
  assert(samples.size() == scans.size() && T_first_scan.size() == scans.size());
  assert(!T_first_scan.empty() && T_first_scan[0].isApprox(Eigen::Isometry3d::Identity()) &&
         "the first scan is the gauge");
  const auto start = std::chrono::steady_clock::now();
  GlobalResult result;
  std::vector<PoseParameters> poses;
  for (const Eigen::Isometry3d& T : T_first_scan) poses.push_back(PoseParameters::from(T));
  std::vector<SampleCloud> thinned;
  for (const SampleCloud& cloud : samples) thinned.push_back(thin(cloud, settings.max_samples));
  // Rounds run on the thinned samples until the poses stop moving (then the
  // refinement has converged); one more round on all samples polishes them:
  // the cheap rounds do the moving, the last one the last tenths of a
  // millimetre.
  bool full = false;
  double gate = settings.initial_gate_m;
  for (int round = 0; round < settings.max_rounds; ++round) {
    result.rounds = round + 1;
    result.correspondences = solve_round(full ? samples : std::span<const SampleCloud>(thinned),
                                         scans, edges, poses, gate, settings);
    double largest_rotation = 0.0;
    double largest_translation = 0.0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      const auto [rotation, translation] = pose_change(T_first_scan[i], poses[i].isometry());
      largest_rotation = std::max(largest_rotation, rotation);
      largest_translation = std::max(largest_translation, translation);
      T_first_scan[i] = poses[i].isometry();
    }
    if (full) break;
    gate = std::max(settings.icp.min_gate_m, 0.5 * gate);
    if (largest_rotation < settings.icp.stop_rotation_rad &&
        largest_translation < settings.icp.stop_translation_m) {
      result.converged = true;
      full = true;
    }
  }
  result.T_first_scan = std::move(T_first_scan);
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration

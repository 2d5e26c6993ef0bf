// Point-to-plane ICP (Chen and Medioni 1992) with projective data association
// (Blais and Levine 1995): the target is a range image, so the match of a
// sample is the pixel on whose beam it lies, found in O(1).
#include "registration/icp.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include "core/parallel.hpp"
#include "core/timing.hpp"
#include "registration/association.hpp"
#include "registration/point_to_plane_costs.hpp"
#include "registration/pose_parameters.hpp"

namespace scanbench::registration {
namespace {

using Clock = std::chrono::steady_clock;

AssociationGate gate_of(double max_distance_m, const IcpSettings& settings) {
  const double angle_rad = settings.max_normal_angle_deg * std::numbers::pi / 180.0;
  return {max_distance_m, std::cos(angle_rad)};
}

// 1.4826 · median |distance|: a standard deviation that outliers do not inflate.
double robust_sigma(const std::vector<PlaneCorrespondence>& matches, const Eigen::Isometry3d& T) {
  if (matches.empty()) return 0.0;
  std::vector<double> distances(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    distances[i] = std::abs(plane_distance(matches[i], T));
  }
  auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;
}

ceres::Solver::Options solver_options(const IcpSettings& settings) {
  ceres::Solver::Options options;
  // Six unknowns: the normal equations are a 6 × 6 dense system.
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.max_num_iterations = settings.solver_iterations;
  options.num_threads = core::worker_count(settings.threads);
  options.logging_type = ceres::SILENT;
  return options;
}

// T_target_source minimising the robust point-to-plane cost of fixed
// correspondences, from `T`. The correspondences are redone after every
// solve, so a few Levenberg-Marquardt steps suffice.
Eigen::Isometry3d solve_pose(const std::vector<PlaneCorrespondence>& matches,
                             const Eigen::Isometry3d& T, double loss_scale_m,
                             const ceres::Solver::Options& options) {
  PoseParameters pose = PoseParameters::from(T);
  ceres::Problem problem;
  problem.AddParameterBlock(pose.rotation, 4, new ceres::EigenQuaternionManifold);
  problem.AddParameterBlock(pose.translation, 3);
  for (std::span<const PlaneCorrespondence> block : correspondence_blocks(matches)) {
    problem.AddResidualBlock(new PointToPlaneCost(block, loss_scale_m), nullptr, pose.rotation,
                             pose.translation);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  return pose.isometry();
}

}  // namespace

IcpResult point_to_plane_icp(const SampleCloud& source, const PreparedScan& target,
                             const Eigen::Isometry3d& initial, const IcpSettings& settings,
                             const SampleCloud* target_sample) {
  const Clock::time_point start = Clock::now();
  std::optional<SampleIndex> nearest;
  if (target_sample != nullptr) nearest.emplace(*target_sample);
  IcpResult result;
  result.T_target_source = initial;
  const ceres::Solver::Options options = solver_options(settings);
  double gate = std::max(settings.initial_gate_m, settings.min_gate_m);
  const SampleCloud rough = nearest ? thin(source, settings.closest_point_samples) : SampleCloud{};
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    const bool closest_point = nearest && gate > settings.projective_gate_m;
    const SampleCloud& samples = closest_point ? rough : source;
    const std::vector<PlaneCorrespondence> matches = plane_correspondences(
        samples, target,
        associate_samples(samples, target, result.T_target_source, gate_of(gate, settings),
                          settings.threads, closest_point ? &*nearest : nullptr));
    result.iterations = iteration + 1;
    if (matches.size() < settings.min_correspondences) break;
    // The loss follows the gate: wide while the pose is far off, so that the
    // few matches of a rough start all pull; tight at the end.
    const Eigen::Isometry3d next = solve_pose(matches, result.T_target_source,
                                              std::max(settings.loss_scale_m, gate / 4.0), options);
    const auto [rotation, translation] = pose_change(result.T_target_source, next);
    result.T_target_source = next;
    const double sigma = robust_sigma(matches, next);
    // The gate follows the residuals, but halves at most per iteration: a
    // robust sigma reflects the surfaces that already fit (the ground, long
    // walls), and a sudden collapse would drop the few that still hold the
    // pose along the directions those leave free.
    gate = std::clamp(settings.distance_sigmas * sigma,
                      std::max(settings.min_gate_m, gate * settings.min_gate_ratio), gate);
    const bool still =
        rotation < settings.stop_rotation_rad && translation < settings.stop_translation_m;
    if (still && !closest_point) {
      result.converged = true;
      break;
    }
    // Closest points that no longer move the pose have done their part.
    if (still) gate = std::min(gate, settings.projective_gate_m);
  }
  const AlignmentQuality quality =
      measure_alignment(source, target, result.T_target_source, settings);
  result.correspondences = quality.correspondences;
  result.overlap = quality.overlap;
  result.rms_m = quality.rms_m;
  result.free_space_violation = quality.free_space_violation;
  result.converged = result.converged && quality.correspondences >= settings.min_correspondences;
  result.seconds = core::seconds_since(start);
  return result;
}

namespace {

// The quality of a pose from its association with `target` (a prepared
// scan or a patch of one).
template <typename Target>
AlignmentQuality quality_of(const SampleCloud& source, const Target& target,
                            const ProjectiveAssociation& associated,
                            const Eigen::Isometry3d& T_target_source) {
  const std::vector<Correspondence>& matches = associated.matches;
  AlignmentQuality quality;
  quality.correspondences = matches.size();
  quality.overlap = source.size() > 0 ? static_cast<double>(matches.size()) / source.size() : 0.0;
  double sum_squared = 0.0;
  for (const PlaneCorrespondence& c : plane_correspondences(source, target, matches)) {
    const double d = plane_distance(c, T_target_source);
    sum_squared += d * d;
  }
  quality.rms_m = matches.empty() ? 0.0 : std::sqrt(sum_squared / matches.size());
  quality.free_space_violation = associated.free_space_violation;
  return quality;
}

}  // namespace

AlignmentQuality measure_alignment(const SampleCloud& source, const PreparedScan& target,
                                   const Eigen::Isometry3d& T_target_source,
                                   const IcpSettings& settings) {
  return quality_of(
      source, target,
      associate_with_free_space(source, target, T_target_source,
                                gate_of(settings.min_gate_m, settings), settings.threads),
      T_target_source);
}

std::optional<AlignmentQuality> measure_alignment(const SampleCloud& source,
                                                  const PatchedTarget& target,
                                                  const Eigen::Isometry3d& T_target_source,
                                                  const IcpSettings& settings) {
  const std::optional<ProjectiveAssociation> associated = associate_with_free_space(
      source, target, T_target_source, gate_of(settings.min_gate_m, settings), settings.threads);
  if (!associated) return std::nullopt;
  return quality_of(source, target, *associated, T_target_source);
}

}  // namespace scanbench::registration

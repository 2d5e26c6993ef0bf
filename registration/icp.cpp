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

#include "acquisition/parallel.hpp"
#include "acquisition/timing.hpp"
#include "registration/association.hpp"
#include "registration/point_to_plane_residual.hpp"
#include "registration/pose_parameters.hpp"

namespace scanbench::registration {
namespace {

using Clock = std::chrono::steady_clock;

AssociationGate gate_of(double max_distance_m, const IcpSettings& settings) {
  const double angle_rad = settings.max_normal_angle_deg * std::numbers::pi / 180.0;
  return {max_distance_m, std::cos(angle_rad)};
}

double plane_distance(const SampleCloud& source, const PreparedScan& target,
                      const Eigen::Isometry3d& T, const Correspondence& c) {
  const auto k = static_cast<std::size_t>(c.pixel);
  const Eigen::Vector3d p = T * source.points[c.sample].cast<double>();
  return target.geometry->normal[k].cast<double>().dot(p - target.points[k].cast<double>());
}

// 1.4826 · median |distance|: a standard deviation that outliers do not inflate.
double robust_sigma(const SampleCloud& source, const PreparedScan& target,
                    const Eigen::Isometry3d& T, const std::vector<Correspondence>& matches) {
  if (matches.empty()) return 0.0;
  std::vector<double> distances(matches.size());
  for (std::size_t i = 0; i < matches.size(); ++i) {
    distances[i] = std::abs(plane_distance(source, target, T, matches[i]));
  }
  auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;
}

// One Ceres problem for the whole run: a residual per sample, switched on
// and off through its PlaneMatch.
class IcpProblem {
 public:
  IcpProblem(const SampleCloud& source, const Eigen::Isometry3d& initial,
             const IcpSettings& settings)
      : pose_(PoseParameters::from(initial)),
        loss_(new ceres::CauchyLoss(settings.loss_scale_m), ceres::TAKE_OWNERSHIP) {
    sources_.reserve(source.size());
    for (const Eigen::Vector3f& p : source.points) sources_.push_back(p.cast<double>());
    matches_.resize(source.size());
    ceres::Problem::Options options;
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(options);
    problem_->AddParameterBlock(pose_.rotation, 4, new ceres::EigenQuaternionManifold);
    problem_->AddParameterBlock(pose_.translation, 3);
    for (std::size_t s = 0; s < sources_.size(); ++s) {
      auto* cost = new ceres::AutoDiffCostFunction<PointToPlaneResidual, 1, 4, 3>(
          new PointToPlaneResidual(sources_[s], matches_[s]));
      problem_->AddResidualBlock(cost, &loss_, pose_.rotation, pose_.translation);
    }
    solver_options_.linear_solver_type = ceres::DENSE_QR;
    solver_options_.max_num_iterations = 10;
    solver_options_.num_threads = acquisition::worker_count(settings.threads);
    solver_options_.logging_type = ceres::SILENT;
  }

  Eigen::Isometry3d pose() const { return pose_.isometry(); }

  // Activates exactly the given correspondences, then solves with a Cauchy
  // loss of scale `loss_scale_m`.
  void solve(const PreparedScan& target, const std::vector<Correspondence>& matches,
             double loss_scale_m) {
    loss_.Reset(new ceres::CauchyLoss(loss_scale_m), ceres::TAKE_OWNERSHIP);
    for (PlaneMatch& m : matches_) m.weight = 0.0;
    for (const Correspondence& c : matches) {
      const auto k = static_cast<std::size_t>(c.pixel);
      matches_[c.sample] = {target.points[k].cast<double>(),
                            target.geometry->normal[k].cast<double>(), 1.0};
    }
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options_, problem_.get(), &summary);
  }

 private:
  PoseParameters pose_;
  ceres::LossFunctionWrapper loss_;
  std::vector<Eigen::Vector3d> sources_;
  std::vector<PlaneMatch> matches_;
  std::unique_ptr<ceres::Problem> problem_;
  ceres::Solver::Options solver_options_;
};

}  // namespace

IcpResult point_to_plane_icp(const SampleCloud& source, const PreparedScan& target,
                             const Eigen::Isometry3d& initial, const IcpSettings& settings,
                             const SampleCloud* target_sample) {
  const Clock::time_point start = Clock::now();
  std::optional<SampleIndex> nearest;
  if (target_sample != nullptr) nearest.emplace(*target_sample);
  IcpResult result;
  result.T_target_source = initial;
  IcpProblem problem(source, initial, settings);
  double gate = std::max(settings.initial_gate_m, settings.min_gate_m);
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    const std::vector<Correspondence> matches = associate_samples(
        source, target, result.T_target_source, gate_of(gate, settings), settings.threads,
        nearest && gate > settings.projective_gate_m ? &*nearest : nullptr);
    result.iterations = iteration + 1;
    if (matches.size() < settings.min_correspondences) break;
    // The loss follows the gate: wide while the pose is far off, so that the
    // few matches of a rough start all pull; tight at the end.
    problem.solve(target, matches, std::max(settings.loss_scale_m, gate / 4.0));
    const Eigen::Isometry3d next = problem.pose();
    const auto [rotation, translation] = pose_change(result.T_target_source, next);
    result.T_target_source = next;
    const double previous_gate = gate;
    const double sigma = robust_sigma(source, target, next, matches);
    gate = std::clamp(settings.distance_sigmas * sigma, settings.min_gate_m, gate);
    const bool projective = !nearest || previous_gate <= settings.projective_gate_m;
    if (projective && rotation < settings.stop_rotation_rad &&
        translation < settings.stop_translation_m) {
      result.converged = true;
      break;
    }
  }
  const AlignmentQuality quality =
      measure_alignment(source, target, result.T_target_source, settings);
  result.correspondences = quality.correspondences;
  result.overlap = quality.overlap;
  result.rms_m = quality.rms_m;
  result.converged = result.converged && quality.correspondences >= settings.min_correspondences;
  result.seconds = acquisition::seconds_since(start);
  return result;
}

AlignmentQuality measure_alignment(const SampleCloud& source, const PreparedScan& target,
                                   const Eigen::Isometry3d& T_target_source,
                                   const IcpSettings& settings) {
  const std::vector<Correspondence> matches = associate_samples(
      source, target, T_target_source, gate_of(settings.min_gate_m, settings), settings.threads);
  AlignmentQuality quality;
  quality.correspondences = matches.size();
  quality.overlap = source.size() > 0 ? static_cast<double>(matches.size()) / source.size() : 0.0;
  double sum_squared = 0.0;
  for (const Correspondence& c : matches) {
    const double d = plane_distance(source, target, T_target_source, c);
    sum_squared += d * d;
  }
  quality.rms_m = matches.empty() ? 0.0 : std::sqrt(sum_squared / matches.size());
  return quality;
}

}  // namespace scanbench::registration

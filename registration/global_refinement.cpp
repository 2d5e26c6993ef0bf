// Joint point-to-plane refinement of all poses (a multi-view ICP in the
// spirit of Pulli 1999) on the pose graph of the measured pairs: each round
// associates every edge and reduces its correspondences to a quadratic in
// the edge's relative pose (Lu and Milios 1997), then solves the graph.
#include "registration/global_refinement.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include "core/parallel.hpp"
#include "core/timing.hpp"
#include "registration/association.hpp"
#include "registration/point_to_plane_costs.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {
namespace {

// An edge's robust point-to-plane cost for fixed correspondences, as the
// Gauss-Newton quadratic in a small motion ξ = (ω, v) of the relative pose,
// T_target_source = exp(ξ) · T0 (rotation first, in the target's frame):
// with each match's robust residual ρ_i and its derivative J_i by ξ,
//   Σ (ρ_i + J_iᵀ ξ)² = (ξ − ξ*)ᵀ H (ξ − ξ*) + const,  H = Σ J_i J_iᵀ,
// ξ* = −H⁻¹ Σ ρ_i J_i. The sum of the edges' quadratics is the Gauss-Newton
// model of the joint problem over all correspondences (Jacobians and robust
// weights frozen at the round's poses), so memory holds 6 × 6 numbers per
// edge instead of every correspondence; the rounds re-associate and
// re-linearise.
struct EdgeQuadratic {
  Eigen::Isometry3d T0 = Eigen::Isometry3d::Identity();  // target ← source at linearisation
  Eigen::Matrix<double, 6, 6> sqrt_information = Eigen::Matrix<double, 6, 6>::Zero();  // Lᵀ
  Eigen::Matrix<double, 6, 1> step = Eigen::Matrix<double, 6, 1>::Zero();              // ξ*
  std::size_t correspondences = 0;
};

EdgeQuadratic edge_quadratic(std::span<const PlaneCorrespondence> matches,
                             const Eigen::Isometry3d& T0, double loss_scale_m) {
  EdgeQuadratic edge;
  edge.T0 = T0;
  edge.correspondences = matches.size();
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  for (const PlaneCorrespondence& m : matches) {
    const Eigen::Vector3d moved = T0 * m.sample;
    const RobustResidual robust = cauchy_residual(m.normal.dot(moved - m.point), loss_scale_m);
    Eigen::Matrix<double, 6, 1> J;
    J << moved.cross(m.normal), m.normal;
    J *= robust.slope;
    H.noalias() += J * J.transpose();
    g += robust.value * J;
  }
  // A tiny ridge keeps the factorisation defined along directions the
  // matches leave free (a single plane); it moves nothing the matches fix.
  H.diagonal().array() += 1e-12 * std::max(H.trace(), 1.0);
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(H);
  edge.step = -llt.solve(g);
  edge.sqrt_information = llt.matrixU();
  return edge;
}

// Lᵀ (ξ − ξ*), ξ the motion of the edge's relative pose from T0 at the
// poses T_a, T_b (first-order logarithm: the motions are small).
struct EdgeCost {
  EdgeQuadratic edge;

  template <typename T>
  bool operator()(const T* q_a, const T* t_a, const T* q_b, const T* t_b, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> R_a(q_a);
    const Eigen::Map<const Eigen::Quaternion<T>> R_b(q_b);
    const Eigen::Map<const Vector3> ta(t_a);
    const Eigen::Map<const Vector3> tb(t_b);
    const Eigen::Quaternion<T> R_ba = R_b.conjugate() * R_a;
    const Vector3 t_ba = R_b.conjugate() * (ta - tb);
    const Eigen::Matrix<T, 3, 3> D =
        R_ba.toRotationMatrix() * edge.T0.linear().transpose().template cast<T>();
    Eigen::Matrix<T, 6, 1> xi;
    xi << T(0.5) * (D(2, 1) - D(1, 2)), T(0.5) * (D(0, 2) - D(2, 0)), T(0.5) * (D(1, 0) - D(0, 1)),
        t_ba - D * edge.T0.translation().template cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r = edge.sqrt_information.template cast<T>() * (xi - edge.step.template cast<T>());
    return true;
  }
};

ceres::Solver::Options solver_options(const GlobalSettings& settings) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = settings.solver_iterations;
  options.num_threads = core::worker_count(settings.icp.threads);
  options.logging_type = ceres::SILENT;
  return options;
}

// One round: associate every edge at the current poses, through its
// patch or its target scan, and reduce it to its quadratic, then solve the
// pose graph. The edges enter the problem in their own order. `sources`
// are the round's samples (all of `samples`, or thinned); a patch made
// anew holds the pixels of all. Returns the number of correspondences used.
std::size_t solve_round(SampleShelf& samples, SampleShelf& sources, ScanStream& scans,
                        EdgePatches& patches, std::span<const ScanEdge> edges,
                        std::vector<PoseParameters>& poses, double gate_m,
                        const GlobalSettings& settings) {
  const double min_cos = std::cos(settings.icp.max_normal_angle_deg * std::numbers::pi / 180.0);
  const AssociationGate gate{gate_m, min_cos};
  std::vector<std::optional<EdgeQuadratic>> quadratics(edges.size());
  const auto T_target_source = [&](std::size_t e) {
    const auto a = static_cast<std::size_t>(edges[e].source);
    const auto b = static_cast<std::size_t>(edges[e].target);
    return Eigen::Isometry3d(poses[b].isometry().inverse() * poses[a].isometry());
  };
  const auto reduce = [&](std::size_t e, const std::vector<PlaneCorrespondence>& matches) {
    if (matches.size() < settings.icp.min_correspondences) return;
    quadratics[e] = edge_quadratic(matches, T_target_source(e), settings.icp.loss_scale_m);
  };
  patches.visit(
      scans, edges,
      [&](const PatchedTarget& target, std::size_t e) {
        const std::shared_ptr<const SampleCloud> source =
            sources.get(static_cast<std::size_t>(edges[e].source));
        const std::optional<std::vector<Correspondence>> matches =
            associate_samples(*source, target, T_target_source(e), gate, settings.icp.threads);
        if (!matches) return false;
        reduce(e, plane_correspondences(*source, target, *matches));
        return true;
      },
      [&](const PreparedScan& target, std::size_t e) {
        const auto a = static_cast<std::size_t>(edges[e].source);
        const std::shared_ptr<const SampleCloud> source = sources.get(a);
        reduce(e, plane_correspondences(*source, target,
                                        associate_samples(*source, target, T_target_source(e), gate,
                                                          settings.icp.threads)));
        patches.make(edges[e], *samples.get(a), target, T_target_source(e));
      });
  ceres::Problem problem;
  std::size_t total = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (!quadratics[e]) continue;
    PoseParameters& source = poses[static_cast<std::size_t>(edges[e].source)];
    PoseParameters& target = poses[static_cast<std::size_t>(edges[e].target)];
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<EdgeCost, 6, 4, 3, 4, 3>(new EdgeCost{*quadratics[e]}),
        nullptr, source.rotation, source.translation, target.rotation, target.translation);
    total += quadratics[e]->correspondences;
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

GlobalResult refine_globally(SampleShelf& samples, ScanStream& scans, EdgePatches& patches,
                             std::vector<Eigen::Isometry3d> T_first_scan,
                             std::span<const ScanEdge> edges, const GlobalSettings& settings) {
  assert(samples.size() == scans.size() && T_first_scan.size() == scans.size());
  assert(!T_first_scan.empty() && T_first_scan[0].isApprox(Eigen::Isometry3d::Identity()) &&
         "the first scan is the gauge");
  const auto start = std::chrono::steady_clock::now();
  GlobalResult result;
  std::vector<PoseParameters> poses;
  for (const Eigen::Isometry3d& T : T_first_scan) poses.push_back(PoseParameters::from(T));
  SampleShelf thinned(samples.size(), kSamplesKept);
  for (std::size_t k = 0; k < samples.size(); ++k)
    thinned.put(k, thin(*samples.get(k), settings.max_samples));
  // Rounds run on the thinned samples until the poses stop moving (then the
  // refinement has converged); one more round on all samples polishes them:
  // the cheap rounds do the moving, the last one the last tenths of a
  // millimetre.
  bool full = false;
  double gate = settings.initial_gate_m;
  for (int round = 0; round < settings.max_rounds; ++round) {
    result.rounds = round + 1;
    result.correspondences = solve_round(samples, full ? samples : thinned, scans, patches, edges,
                                         poses, gate, settings);
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

// Fine registration of one scan against another: point-to-plane ICP solved
// with Ceres, with projective data association into the target's grid.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>

#include "registration/prepared_scan.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/target_patch.hpp"

namespace scanbench::registration {

struct IcpSettings {
  // Association gate of the first iteration [m]: how far off the initial
  // pose may be, locally. Later gates shrink to distance_sigmas robust
  // standard deviations of the residuals, but not below min_gate_m.
  double initial_gate_m = 2.0;
  double min_gate_m = 0.05;
  // While the gate is wider than this [m], samples are matched to the
  // closest point of a target sample (when one is given); below it, by
  // projection into the target's grid.
  double projective_gate_m = 0.3;
  // The closest-point iterations use at most this many source samples: they
  // only have to bring the pose within the projective gate, and a kd-tree
  // query costs far more than a projection.
  std::size_t closest_point_samples = 4000;
  double distance_sigmas = 3.0;
  double min_gate_ratio = 0.5;  // the gate shrinks at most by this factor per iteration
  // Normals of matched points differ by at most this [deg].
  double max_normal_angle_deg = 25.0;
  // Scale of the Cauchy loss on the point-to-plane distance [m] at the end:
  // a few times the range noise, so residuals of moving objects or changed
  // surfaces weigh little. Early iterations use a quarter of the gate.
  double loss_scale_m = 0.02;
  int max_iterations = 50;
  // Levenberg-Marquardt steps of Ceres per set of correspondences.
  int solver_iterations = 5;
  // Stop when one iteration moves the pose less than both of these.
  double stop_rotation_rad = 3e-5;  // 0.0017°
  double stop_translation_m = 3e-4;
  // Fewer correspondences than this: not converged.
  std::size_t min_correspondences = 50;
  int threads = 0;  // 0 = all cores; results do not depend on it
};

struct IcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  // True when the pose stopped moving with enough correspondences; false
  // when iterations ran out or the correspondences were too few.
  bool converged = false;
  int iterations = 0;
  std::size_t correspondences = 0;    // of the final pose
  double overlap = 0.0;               // correspondences / samples
  double rms_m = 0.0;                 // point-to-plane RMS of those [m]
  double free_space_violation = 0.0;  // of the final pose (measure_alignment)
  double seconds = 0.0;
};

// Refines T_target_source (source scan frame → target scan frame) from
// `initial`. `source` is a sample of the source scan (sample_scan), `target`
// the prepared target scan; `target_sample`, when given, a sample of the
// target for the closest-point iterations of a rough start.
IcpResult point_to_plane_icp(const SampleCloud& source, const PreparedScan& target,
                             const Eigen::Isometry3d& initial, const IcpSettings& settings,
                             const SampleCloud* target_sample = nullptr);

// Point-to-plane RMS [m], the correspondences and the free-space violations
// of a given pose, at the final gate of ICP (min_gate_m): the overlap and
// residual report of a pose without moving it.
struct AlignmentQuality {
  std::size_t correspondences = 0;
  double overlap = 0.0;  // correspondences / samples
  double rms_m = 0.0;
  // free_space_violation (association.hpp) at the same gate.
  double free_space_violation = 0.0;
};
AlignmentQuality measure_alignment(const SampleCloud& source, const PreparedScan& target,
                                   const Eigen::Isometry3d& T_target_source,
                                   const IcpSettings& settings);
// The same through a patch of the target; nullopt when a sample falls on a
// pixel the patch does not hold (association.hpp).
std::optional<AlignmentQuality> measure_alignment(const SampleCloud& source,
                                                  const PatchedTarget& target,
                                                  const Eigen::Isometry3d& T_target_source,
                                                  const IcpSettings& settings);

}  // namespace scanbench::registration

// PCL's IterativeClosestPointWithNormals (point-to-plane ICP on a kd-tree) as
// the peer of our ICP (bench "registration"), run in stages whose maximum
// correspondence distance follows our ICP's gate schedule. PCL headers stay
// in pcl_icp.cpp.
#pragma once

#include <Eigen/Geometry>

#include "registration/icp.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::bench {

struct PclIcpSettings {
  // The schedule of our ICP, read from its settings: the first stage's gate
  // (initial_gate_m), the rule for the next (distance_sigmas robust σ of the
  // point-to-plane residuals, clamped to [max(min_gate_m, gate ·
  // min_gate_ratio), gate]), the stop thresholds (stop_rotation_rad,
  // stop_translation_m), the iteration cap (max_iterations, over all
  // stages), min_correspondences, and, with thin_wide_stages,
  // projective_gate_m and closest_point_samples. Its association, normal
  // test, loss and solver settings are not PCL's and are not read.
  registration::IcpSettings schedule;
  // true: the next gate follows the residuals as ours does; the run stops
  // when a stage at a gate ≤ projective_gate_m moves the pose less than the
  // stop thresholds, and a stage at a wider gate that does not move the pose
  // drops the gate to projective_gate_m (as ours does). false: the gate
  // halves (min_gate_ratio) every stage down to min_gate_m, and the run stops
  // when a stage at min_gate_m does not move the pose.
  bool adaptive_gate = true;
  // PCL iterations per stage (one gate); PCL's own convergence test (the
  // stop thresholds) ends a stage early.
  int iterations_per_stage = 1;
  // While the gate is wider than projective_gate_m, use every k-th source
  // sample, at most closest_point_samples, as our closest-point iterations do.
  bool thin_wide_stages = true;
  // > 0: PCL's CorrespondenceRejectorSurfaceNormal drops matches whose
  // normals differ by more than this [deg].
  double max_normal_angle_deg = 0.0;
  // > 0: PCL's CorrespondenceRejectorMedianDistance drops matches farther
  // than this many times the median match distance.
  double median_factor = 0.0;
  // PCL's symmetric point-to-plane objective (Rusinkiewicz 2019) instead of
  // the point-to-plane linear least squares.
  bool symmetric_objective = false;
  // Reciprocal (mutual nearest neighbour) correspondences only.
  bool reciprocal = false;
};

struct PclIcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  // The last stage moved the pose less than the stop thresholds with at
  // least min_correspondences matches.
  bool converged = false;
  int iterations = 0;  // PCL iterations over all stages
  int stages = 0;
  double final_gate_m = 0.0;  // the maximum correspondence distance of the last stage
  double seconds = 0.0;       // kd-tree of the target included
};

// Aligns `source` to `target` (points with normals, each in its scan frame)
// from `initial` (source frame → target frame), single-threaded (PCL's ICP
// has no threading).
PclIcpResult pcl_point_to_plane_icp(const registration::SampleCloud& source,
                                    const registration::SampleCloud& target,
                                    const Eigen::Isometry3d& initial,
                                    const PclIcpSettings& settings);

}  // namespace scanbench::bench

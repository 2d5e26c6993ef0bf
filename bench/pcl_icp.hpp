// PCL's IterativeClosestPointWithNormals (point-to-plane ICP on a kd-tree) as
// the peer of our ICP (bench "registration"). PCL headers stay in pcl_icp.cpp.
#pragma once

#include <Eigen/Geometry>

#include "registration/sample_cloud.hpp"

namespace scanbench::bench {

struct PclIcpSettings {
  double max_correspondence_m = 0.3;
  int max_iterations = 50;
  double transformation_epsilon = 1e-10;  // squared change of the transform
};

struct PclIcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  bool converged = false;
  double seconds = 0.0;  // kd-tree of the target included
};

// Aligns `source` to `target` (points with normals, each in its scan frame)
// from `initial` (source frame → target frame).
PclIcpResult pcl_point_to_plane_icp(const registration::SampleCloud& source,
                                    const registration::SampleCloud& target,
                                    const Eigen::Isometry3d& initial,
                                    const PclIcpSettings& settings);

}  // namespace scanbench::bench

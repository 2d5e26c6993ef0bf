#include "bench/pcl_icp.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <chrono>

#include "core/timing.hpp"
#include "registration/pcl_sample_cloud.hpp"

namespace scanbench::bench {

using Cloud = pcl::PointCloud<pcl::PointNormal>;

PclIcpResult pcl_point_to_plane_icp(const registration::SampleCloud& source,
                                    const registration::SampleCloud& target,
                                    const Eigen::Isometry3d& initial,
                                    const PclIcpSettings& settings) {
  const Cloud::Ptr source_cloud = registration::to_pcl_cloud(source);
  const Cloud::Ptr target_cloud = registration::to_pcl_cloud(target);
  const auto start = std::chrono::steady_clock::now();
  pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
  icp.setInputSource(source_cloud);
  icp.setInputTarget(target_cloud);
  icp.setMaxCorrespondenceDistance(settings.max_correspondence_m);
  icp.setMaximumIterations(settings.max_iterations);
  icp.setTransformationEpsilon(settings.transformation_epsilon);
  Cloud aligned;
  icp.align(aligned, initial.matrix().cast<float>());
  PclIcpResult result;
  result.seconds = core::seconds_since(start);
  result.converged = icp.hasConverged();
  result.T_target_source.matrix() = icp.getFinalTransformation().cast<double>();
  return result;
}

}  // namespace scanbench::bench

#include "bench/pcl_icp.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <chrono>

namespace scanbench::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;

Cloud::Ptr to_pcl(const registration::SampleCloud& sample) {
  auto cloud = std::make_shared<Cloud>();
  cloud->reserve(sample.size());
  for (std::size_t i = 0; i < sample.size(); ++i) {
    pcl::PointNormal p;
    // Component-wise: PCL's 4-float maps trip GCC 12's array-bounds check.
    p.x = sample.points[i].x();
    p.y = sample.points[i].y();
    p.z = sample.points[i].z();
    p.normal_x = sample.normals[i].x();
    p.normal_y = sample.normals[i].y();
    p.normal_z = sample.normals[i].z();
    p.curvature = 0.0f;
    cloud->push_back(p);
  }
  return cloud;
}

}  // namespace

PclIcpResult pcl_point_to_plane_icp(const registration::SampleCloud& source,
                                    const registration::SampleCloud& target,
                                    const Eigen::Isometry3d& initial,
                                    const PclIcpSettings& settings) {
  const Cloud::Ptr source_cloud = to_pcl(source);
  const Cloud::Ptr target_cloud = to_pcl(target);
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
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.converged = icp.hasConverged();
  result.T_target_source.matrix() = icp.getFinalTransformation().cast<double>();
  return result;
}

}  // namespace scanbench::bench

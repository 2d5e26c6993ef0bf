// A SampleCloud as a PCL cloud of points with normals, for the PCL peers.
// Include only from the bench files that use PCL (pcl_icp.cpp).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

inline pcl::PointCloud<pcl::PointNormal>::Ptr to_pcl_cloud(const SampleCloud& sample) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointNormal>>();
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

}  // namespace scanbench::registration

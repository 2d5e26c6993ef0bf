#include "registration/point_index.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cassert>
#include <vector>

namespace scanbench::registration {

struct PointIndex::Impl {
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  std::vector<std::int64_t> pixel_of_point;  // kd-tree point → caller's index
};

PointIndex::PointIndex(std::span<const Eigen::Vector3f> points,
                       std::span<const std::uint8_t> usable)
    : impl_(std::make_unique<Impl>()) {
  assert(points.size() == usable.size() && "one usable flag per point");
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!usable[i]) continue;
    cloud->push_back(pcl::PointXYZ(points[i].x(), points[i].y(), points[i].z()));
    impl_->pixel_of_point.push_back(static_cast<std::int64_t>(i));
  }
  if (!cloud->empty()) impl_->tree.setInputCloud(cloud);
}

PointIndex::~PointIndex() = default;
PointIndex::PointIndex(PointIndex&&) noexcept = default;
PointIndex& PointIndex::operator=(PointIndex&&) noexcept = default;

std::int64_t PointIndex::nearest(const Eigen::Vector3f& p) const {
  if (impl_->pixel_of_point.empty()) return -1;
  std::vector<int> found(1);
  std::vector<float> squared_distances(1);
  const pcl::PointXYZ query(p.x(), p.y(), p.z());
  if (impl_->tree.nearestKSearch(query, 1, found, squared_distances) < 1) return -1;
  return impl_->pixel_of_point[static_cast<std::size_t>(found[0])];
}

}  // namespace scanbench::registration

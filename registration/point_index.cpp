#include "registration/point_index.hpp"

#include <cassert>
#include <vector>

#include "registration/nearest_points.hpp"

namespace scanbench::registration {

struct PointIndex::Impl {
  std::vector<Eigen::Vector3f> points;                    // the usable points
  std::vector<std::int64_t> pixel_of_point;               // row of points → caller's index
  std::unique_ptr<NearestRows<Eigen::Vector3f, 3>> tree;  // over points
};

PointIndex::PointIndex(std::span<const Eigen::Vector3f> points,
                       std::span<const std::uint8_t> usable)
    : impl_(std::make_unique<Impl>()) {
  assert(points.size() == usable.size() && "one usable flag per point");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!usable[i]) continue;
    impl_->points.push_back(points[i]);
    impl_->pixel_of_point.push_back(static_cast<std::int64_t>(i));
  }
  if (!impl_->points.empty()) {
    impl_->tree = std::make_unique<NearestRows<Eigen::Vector3f, 3>>(impl_->points);
  }
}

PointIndex::~PointIndex() = default;
PointIndex::PointIndex(PointIndex&&) noexcept = default;
PointIndex& PointIndex::operator=(PointIndex&&) noexcept = default;

std::int64_t PointIndex::nearest(const Eigen::Vector3f& p) const {
  if (!impl_->tree) return -1;
  std::vector<std::size_t> found;
  std::vector<float> squared_distances;
  impl_->tree->nearest(p.data(), 1, found, squared_distances);
  if (found.empty()) return -1;
  return impl_->pixel_of_point[found[0]];
}

}  // namespace scanbench::registration

// Nearest-neighbour index over a scan's points: the association fallback for
// grids without a regular angle model (per-pixel directions), where the pixel
// a point projects to cannot be computed. A k-d tree (nearest_points.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>

namespace scanbench::registration {

class PointIndex {
 public:
  // Indexes points[i] for every i with usable[i] != 0 (points in one frame
  // [m]; the spans must be equally long). The index copies what it needs.
  PointIndex(std::span<const Eigen::Vector3f> points, std::span<const std::uint8_t> usable);
  ~PointIndex();
  PointIndex(PointIndex&&) noexcept;
  PointIndex& operator=(PointIndex&&) noexcept;

  // Index i of the usable point nearest to `p` (same frame), or -1 when the
  // index is empty. Safe to call from several threads at once.
  std::int64_t nearest(const Eigen::Vector3f& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace scanbench::registration

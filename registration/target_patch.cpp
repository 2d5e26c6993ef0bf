#include "registration/target_patch.hpp"

#include <algorithm>
#include <cassert>

namespace scanbench::registration {

std::int64_t TargetPatch::slot_of(std::int64_t pixel) const {
  const auto found = std::lower_bound(pixels.begin(), pixels.end(), pixel);
  if (found == pixels.end() || *found != pixel) return -1;
  return found - pixels.begin();
}

TargetPatch patch_of(const SampleCloud& source, const PreparedScan& target,
                     const Eigen::Isometry3d& T_target_source, int margin) {
  assert(target.grid && !target.points.empty() && "a prepared spherical grid with its points");
  assert(margin >= 0);
  const std::int64_t rows = target.scan->rows;
  const std::int64_t columns = target.scan->columns;
  // The same float transform as association, so that a patch made at a
  // pose holds every pixel association at that pose reads.
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  TargetPatch patch;
  for (const Eigen::Vector3f& sample : source.points) {
    const std::int64_t pixel = target.grid->pixel_of(Eigen::Vector3f(T * sample));
    if (pixel < 0) continue;
    const std::int64_t row = pixel / columns;
    const std::int64_t column = pixel % columns;
    for (std::int64_t r = std::max<std::int64_t>(0, row - margin);
         r <= std::min(rows - 1, row + margin); ++r) {
      for (std::int64_t dc = -margin; dc <= margin; ++dc) {
        patch.pixels.push_back(r * columns + ((column + dc) % columns + columns) % columns);
      }
    }
  }
  std::sort(patch.pixels.begin(), patch.pixels.end());
  patch.pixels.erase(std::unique(patch.pixels.begin(), patch.pixels.end()), patch.pixels.end());
  const std::size_t n = patch.pixels.size();
  patch.range_m.reserve(n);
  patch.points.reserve(n);
  patch.normals.reserve(n);
  patch.footprint_m.reserve(n);
  patch.usable.reserve(n);
  for (const std::int64_t pixel : patch.pixels) {
    const auto k = static_cast<std::size_t>(pixel);
    patch.range_m.push_back(target.scan->range_m[k]);
    patch.points.push_back(target.points[k]);
    patch.normals.push_back(target.geometry->normal[k]);
    patch.footprint_m.push_back(target.geometry->footprint_m[k]);
    patch.usable.push_back(target.usable[k]);
  }
  return patch;
}

}  // namespace scanbench::registration

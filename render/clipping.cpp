#include "render/clipping.hpp"

#include <cmath>

namespace scanbench::render {

bool Clipping::keeps(const Eigen::Vector3f& p) const {
  if (!box.isEmpty() && !box.contains(p)) return false;
  return section_half_width <= 0.0f ||
         std::abs(section_normal.dot(p) - section_offset) <= section_half_width;
}

bool Clipping::excludes(const Eigen::AlignedBox3f& b) const {
  if (b.isEmpty()) return false;
  if (!box.isEmpty() && !box.intersects(b)) return true;
  if (section_half_width <= 0.0f) return false;
  // The box's extent along the normal against the slab.
  const float centre = section_normal.dot(b.center()) - section_offset;
  const float reach = 0.5f * section_normal.cwiseAbs().dot(b.sizes());
  return centre - reach > section_half_width || centre + reach < -section_half_width;
}

}  // namespace scanbench::render

#include "modeling/object_carry.hpp"

#include <cassert>

namespace scanbench::modeling {

namespace {

// The drawn object's box in the drawn scan's frame (near world-aligned: a
// scanner stands level), widened by `margin` of its largest extent. Kept
// in that frame so that float coordinates stay small at georeferenced sites.
Eigen::AlignedBox3f growth_box(const DrawnObject& drawn, double margin) {
  const registration::PreparedScan& scan = *drawn.scan;
  Eigen::AlignedBox3f box;
  for (std::size_t k = 0; k < drawn.labels.size(); ++k) {
    if (drawn.labels[k] != 0 && scan.in_model[k]) box.extend(scan.points[k]);
  }
  if (box.isEmpty()) return box;
  const float widen = static_cast<float>(margin) * box.sizes().maxCoeff();
  box.min().array() -= widen;
  box.max().array() += widen;
  return box;
}

}  // namespace

segmentation::PixelSet carry_object(const DrawnObject& drawn, const CarryTarget& target,
                                    const CarrySettings& settings) {
  const registration::PreparedScan& scan = *target.scan;
  assert(drawn.labels.size() == drawn.scan->in_model.size() && "one label per drawn pixel");
  assert(target.open.size() == scan.in_model.size() && "one byte per target pixel");
  const Eigen::Isometry3d T_drawn_target = drawn.T_world_scan.inverse() * target.T_world_scan;
  const registration::Sightings seen =
      registration::sight_in_source(*drawn.scan, scan, T_drawn_target, settings.transfer);
  const auto labelled = [&](std::size_t q) {
    return drawn.labels[static_cast<std::size_t>(seen.pixel[q])] != 0;
  };
  segmentation::PixelSet carried;
  for (std::size_t q = 0; q < seen.sighting.size(); ++q) {
    if (target.open[q] && seen.sighting[q] == registration::Sighting::kSurface && labelled(q))
      carried.push_back(static_cast<std::uint32_t>(q));
  }
  if (!settings.grow || target.grid == nullptr || carried.empty()) return carried;

  // Where growth may go: open, in the box, and not a place the drawn scan
  // sampled and left out of the object.
  const segmentation::SegmentationGrid& grid = *target.grid;
  const Eigen::AlignedBox3f box = growth_box(drawn, settings.box_margin);
  const Eigen::Isometry3f T_box_target = T_drawn_target.cast<float>();  // composed in double
  std::vector<std::uint8_t> may_grow(seen.sighting.size(), 0);
  for (std::size_t q = 0; q < may_grow.size(); ++q) {
    if (!target.open[q] || !grid.usable[q]) continue;
    if (seen.sighting[q] != registration::Sighting::kUnseen && !labelled(q)) continue;
    may_grow[q] = box.contains(T_box_target * scan.points[q]) ? 1 : 0;
  }
  for (const std::uint32_t q : carried) may_grow[q] = grid.usable[q];
  // A region from each carried pixel not yet reached; what a region takes is
  // closed to the next, so each pixel is grown over once.
  std::vector<std::uint8_t> in_object(may_grow.size(), 0);
  for (const std::uint32_t q : carried) in_object[q] = 1;
  segmentation::RegionGrower grower(grid);
  for (const std::uint32_t seed : carried) {
    if (!may_grow[seed]) continue;
    for (const std::uint32_t q : grower.grow(seed, *settings.grow, may_grow).pixels) {
      may_grow[q] = 0;
      in_object[q] = 1;
    }
  }
  return segmentation::from_mask(in_object);
}

}  // namespace scanbench::modeling

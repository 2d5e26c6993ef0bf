#include "modeling/lod/memory_store.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace scanbench::lod {

void write_lod_store(const std::filesystem::path& file, const Eigen::Vector3d& origin,
                     const std::vector<LodScan>& scans, const std::vector<PointToStore>& points,
                     const OctreeSettings& settings) {
  Eigen::AlignedBox3d box;
  for (const PointToStore& p : points) box.extend(p.position - origin);
  LodHeader header;
  header.origin = origin;
  header.cube = OctreeCube::enclosing(box);
  header.octree = settings;
  std::vector<BuildPoint> built;
  built.reserve(points.size());
  for (const PointToStore& p : points) {
    assert(std::any_of(scans.begin(), scans.end(),
                       [&](const LodScan& s) { return s.index == p.scan; }) &&
           "a point of a scan the store does not name");
    const std::int64_t scan_id = std::find_if(scans.begin(), scans.end(), [&](const LodScan& s) {
                                   return s.index == p.scan;
                                 })->scan_id;
    BuildPoint b;
    b.point.offset = *header.cube.quantize(p.position - origin);
    b.point.object = p.object;
    b.point.pixel = p.pixel;
    b.point.scan = p.scan;
    b.point.intensity =
        static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(p.intensity, 0.0f, 1.0f)));
    if (p.rgb) {
      b.point.flags |= LodPoint::kHasColor;
      b.point.rgb = {(*p.rgb)[0], (*p.rgb)[1], (*p.rgb)[2], 0};
    }
    if (!p.normal.isZero()) {
      b.point.flags |= LodPoint::kHasNormal;
      b.point.normal = encode_unit(p.normal);
    }
    if (p.major_axis.isZero()) {
      b.point.flags |= LodPoint::kRound;
    } else {
      b.point.major_axis = encode_unit(p.major_axis);
    }
    b.point.radii = {to_half(p.radii_m.x()), to_half(p.radii_m.y())};
    b.priority = point_priority(scan_id, p.pixel);
    built.push_back(b);
  }
  LodStoreWriter writer(file, header, scans);
  if (!built.empty()) {
    Subtree root = build_subtree(header.cube, NodeKey{}, std::move(built), settings,
                                 [&](BuiltNode&& node) { writer.put(node); });
    writer.put(finish_node(header.cube, std::move(root)));
  }
  writer.commit();
}

}  // namespace scanbench::lod

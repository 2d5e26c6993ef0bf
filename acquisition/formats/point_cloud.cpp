#include "acquisition/formats/point_cloud.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <utility>

#include "acquisition/local_origin.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

namespace {

// The recorded geometry of `cloud`, padded to the scan's pixels, its
// normals in the scan frame; empty vectors where the cloud has none.
RecordedGeometry recorded_geometry(PointCloud& cloud, const Scan& scan) {
  RecordedGeometry recorded;
  const Eigen::Matrix3f scan_from_file = scan.T_world_scan.linear().cast<float>().transpose();
  if (!cloud.normal.empty()) {
    for (Eigen::Vector3f& n : cloud.normal) {
      const float length = n.norm();
      const bool usable = std::isfinite(length) && length > 1e-12f;
      n = usable ? Eigen::Vector3f(scan_from_file * (n / length)) : Eigen::Vector3f::Zero();
    }
    cloud.normal.resize(scan.pixel_count(), Eigen::Vector3f::Zero());
    recorded.normal = std::move(cloud.normal);
  }
  if (!cloud.footprint_m.empty()) {
    for (float& f : cloud.footprint_m) f = std::isfinite(f) && f > 0.0f ? f : 0.0f;
    cloud.footprint_m.resize(scan.pixel_count(), 0.0f);
    recorded.footprint_m = std::move(cloud.footprint_m);
  }
  return recorded;
}

}  // namespace

ImportedScan scattered_scan(PointCloud&& cloud, const std::filesystem::path& path) {
  const std::size_t n = cloud.points.size();
  if (n == 0)
    throw core::InputError(path.string(), {}, "holds no points: there is nothing to import");
  assert((cloud.intensity.empty() || cloud.intensity.size() == n) &&
         (cloud.rgb.empty() || cloud.rgb.size() == 3 * n) &&
         (cloud.normal.empty() || cloud.normal.size() == n) &&
         (cloud.footprint_m.empty() || cloud.footprint_m.size() == n) &&
         "channels of one value per point");
  ImportedScan out;
  Scan& scan = out.scan;
  scan = make_scattered_scan(n, false, false);
  // The channels become the scan's, padded to its last row.
  if (!cloud.intensity.empty()) {
    cloud.intensity.resize(scan.pixel_count(), 0.0f);
    scan.intensity = std::move(cloud.intensity);
  }
  if (!cloud.rgb.empty()) {
    cloud.rgb.resize(3 * scan.pixel_count(), 0);
    scan.rgb = std::move(cloud.rgb);
  }
  set_scattered_points(scan, std::move(cloud.points));
  out.recorded = recorded_geometry(cloud, scan);
  const std::u8string stem = path.stem().u8string();
  const std::u8string utf8 = path.u8string();
  scan.name = std::string(stem.begin(), stem.end());
  scan.scanner.source_file = std::string(utf8.begin(), utf8.end());
  return out;
}

}  // namespace scanbench::acquisition

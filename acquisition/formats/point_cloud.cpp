#include "acquisition/formats/point_cloud.hpp"

#include <algorithm>
#include <cassert>
#include <string>
#include <utility>

#include "acquisition/local_origin.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {

Scan scattered_scan(PointCloud&& cloud, const std::filesystem::path& path) {
  const std::size_t n = cloud.points.size();
  if (n == 0)
    throw core::InputError(path.string(), {}, "holds no points: there is nothing to import");
  assert((cloud.intensity.empty() || cloud.intensity.size() == n) &&
         (cloud.rgb.empty() || cloud.rgb.size() == 3 * n) && "channels of one value per point");
  Scan scan = make_scattered_scan(n, false, false);
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
  const std::u8string stem = path.stem().u8string();
  const std::u8string utf8 = path.u8string();
  scan.name = std::string(stem.begin(), stem.end());
  scan.scanner.source_file = std::string(utf8.begin(), utf8.end());
  return scan;
}

}  // namespace scanbench::acquisition

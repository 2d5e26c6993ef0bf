#include "acquisition/formats/point_cloud.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/local_origin.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"

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

// One scan of `cloud`, as scattered_scans describes.
ImportedScan one_scan(PointCloud&& cloud, const std::filesystem::path& path) {
  const std::size_t n = cloud.points.size();
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
  out.source.points_in_file = n;
  return out;
}

// The points of `cloud` that `take` lists, with their channels.
PointCloud part_of(const PointCloud& cloud, const std::vector<std::size_t>& take) {
  PointCloud part;
  const auto gather = [&take](const auto& from, auto& to, std::size_t width) {
    if (from.empty()) return;
    to.reserve(width * take.size());
    for (const std::size_t i : take) {
      for (std::size_t k = 0; k < width; ++k) to.push_back(from[width * i + k]);
    }
  };
  gather(cloud.points, part.points, 1);
  gather(cloud.intensity, part.intensity, 1);
  gather(cloud.rgb, part.rgb, 3);
  gather(cloud.normal, part.normal, 1);
  gather(cloud.footprint_m, part.footprint_m, 1);
  return part;
}

// One scan per cube of kCloudTileM that `cloud` touches.
std::vector<ImportedScan> tiles(const PointCloud& cloud, const std::filesystem::path& path) {
  Eigen::Vector3d low = cloud.points.front();
  for (const Eigen::Vector3d& p : cloud.points) low = low.cwiseMin(p);
  std::map<std::array<std::int64_t, 3>, std::vector<std::size_t>> cubes;  // x, then y, then z
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    const Eigen::Vector3d cell = ((cloud.points[i] - low) / kCloudTileM).array().floor();
    cubes[{static_cast<std::int64_t>(cell.x()), static_cast<std::int64_t>(cell.y()),
           static_cast<std::int64_t>(cell.z())}]
        .push_back(i);
  }
  std::vector<ImportedScan> out;
  for (const auto& [cube, take] : cubes) out.push_back(one_scan(part_of(cloud, take), path));
  const std::string stem = out.front().scan.name;  // a copy: naming changes it
  name_tiles(out, stem);
  return out;
}

}  // namespace

void name_tiles(std::span<ImportedScan> tiles, const std::string& name) {
  for (std::size_t k = 0; k < tiles.size(); ++k) {
    std::string& to = tiles[k].scan.name;
    to = name;
    if (tiles.size() > 1) to.append(1, '-').append(std::to_string(k + 1));
  }
}

std::vector<ImportedScan> scattered_scans(PointCloud&& cloud, const std::filesystem::path& path) {
  const std::size_t n = cloud.points.size();
  if (n == 0)
    throw core::InputError(path.string(), {}, "holds no points: there is nothing to import");
  assert((cloud.intensity.empty() || cloud.intensity.size() == n) &&
         (cloud.rgb.empty() || cloud.rgb.size() == 3 * n) &&
         (cloud.normal.empty() || cloud.normal.size() == n) &&
         (cloud.footprint_m.empty() || cloud.footprint_m.size() == n) &&
         "channels of one value per point");
  // Within 625 m of the centroid, the bound of a float range and direction
  // (1.6e-7 of the range) keeps 0.1 mm: one scan for sure. Farther, one scan
  // is tried on a copy, and the cloud is tiled if it fails.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : cloud.points) centroid += p;
  centroid /= static_cast<double>(n);
  double farthest = 0.0;
  for (const Eigen::Vector3d& p : cloud.points)
    farthest = std::max(farthest, (p - centroid).norm());
  std::vector<ImportedScan> out;  // filled by moves: a braced list would copy the scan
  if (1.6e-7 * farthest <= kPromisedRoundTripM) {
    out.push_back(one_scan(std::move(cloud), path));
    return out;
  }
  // The copy and the scan tried on it, then the tiles beside the cloud:
  // about as much again as the cloud and its scan.
  core::check_memory(n * 64, path.string());
  PointCloud copy = cloud;
  out.push_back(one_scan(std::move(copy), path));
  if (out.front().scan.import_round_trip_m <= kPromisedRoundTripM) return out;
  out.clear();
  return tiles(cloud, path);
}

}  // namespace scanbench::acquisition

// PCL's RegionGrowing (Rabbani et al., "Segmentation of point clouds using
// smoothness constraint", ISPRS 2006) and RegionGrowingRGB (Zhan et al.,
// "Color-based segmentation of point sets", 2009) run on a scan's usable
// points. PCL segments a whole scan at once; our grower answers one click.
// Both are given our normals, which bench "geometry" measured as better
// than PCL's own, so the comparison is of the growing alone.
#include "bench/pcl_segmentation.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>
#include <pcl/segmentation/region_growing_rgb.h>

#include <chrono>
#include <numbers>

namespace scanbench::bench {
namespace {

template <typename Point>
struct Input {
  typename pcl::PointCloud<Point>::Ptr cloud = pcl::make_shared<pcl::PointCloud<Point>>();
  pcl::PointCloud<pcl::Normal>::Ptr normals = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  std::vector<std::size_t> pixel;  // the pixel of each point
};

template <typename Point>
Input<Point> make_input(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry,
                        const std::vector<std::uint8_t>& usable) {
  Input<Point> input;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const std::size_t i = scan.index(row, col);
      if (!usable[i]) continue;
      const Eigen::Vector3f p = acquisition::point_in_scan(scan, row, col);
      Point point;
      point.x = p.x(), point.y = p.y(), point.z = p.z();
      if constexpr (std::is_same_v<Point, pcl::PointXYZRGB>) {
        point.r = scan.rgb[3 * i], point.g = scan.rgb[3 * i + 1], point.b = scan.rgb[3 * i + 2];
      }
      input.cloud->push_back(point);
      const Eigen::Vector3f& n = geometry.normal[i];
      input.normals->push_back(pcl::Normal(n.x(), n.y(), n.z(), 1.0f - geometry.confidence[i]));
      input.pixel.push_back(i);
    }
  }
  return input;
}

template <typename Point, typename Segmenter>
PclSegmentationResult run(Segmenter& segmenter, const Input<Point>& input, std::size_t pixels) {
  PclSegmentationResult result;
  const auto start = std::chrono::steady_clock::now();
  auto tree = pcl::make_shared<pcl::search::KdTree<Point>>();
  segmenter.setSearchMethod(tree);
  segmenter.setInputCloud(input.cloud);
  segmenter.setInputNormals(input.normals);
  std::vector<pcl::PointIndices> clusters;
  segmenter.extract(clusters);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.label.assign(pixels, -1);
  for (std::size_t k = 0; k < clusters.size(); ++k) {
    for (const auto index : clusters[k].indices) {
      result.label[input.pixel[static_cast<std::size_t>(index)]] = static_cast<std::int32_t>(k);
    }
  }
  result.segments = clusters.size();
  return result;
}

}  // namespace

PclSegmentationResult segment_with_pcl(const acquisition::Scan& scan,
                                       const acquisition::ScanGeometry& geometry,
                                       const std::vector<std::uint8_t>& usable,
                                       const PclSegmentationSettings& settings) {
  const float smoothness_rad = settings.smoothness_deg * std::numbers::pi_v<float> / 180.0f;
  if (settings.segmenter == PclSegmenter::kRegionGrowing) {
    const Input<pcl::PointXYZ> input = make_input<pcl::PointXYZ>(scan, geometry, usable);
    pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> segmenter;
    segmenter.setNumberOfNeighbours(static_cast<unsigned>(settings.neighbours));
    segmenter.setSmoothnessThreshold(smoothness_rad);
    segmenter.setCurvatureTestFlag(settings.curvature_threshold > 0.0f);
    if (settings.curvature_threshold > 0.0f) {
      segmenter.setCurvatureThreshold(settings.curvature_threshold);
    }
    segmenter.setMinClusterSize(static_cast<pcl::uindex_t>(settings.min_cluster_size));
    return run(segmenter, input, scan.pixel_count());
  }
  const Input<pcl::PointXYZRGB> input = make_input<pcl::PointXYZRGB>(scan, geometry, usable);
  pcl::RegionGrowingRGB<pcl::PointXYZRGB, pcl::Normal> segmenter;
  segmenter.setDistanceThreshold(settings.distance_m);
  segmenter.setPointColorThreshold(settings.point_color_threshold);
  segmenter.setRegionColorThreshold(settings.region_color_threshold);
  segmenter.setMinClusterSize(static_cast<pcl::uindex_t>(settings.min_cluster_size));
  return run(segmenter, input, scan.pixel_count());
}

}  // namespace scanbench::bench

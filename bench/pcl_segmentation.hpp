// PCL's region growing segmenters as the peers of our seeded region growing
// (bench "segmentation"). PCL's types stay in pcl_segmentation.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::bench {

enum class PclSegmenter {
  kRegionGrowing,     // pcl::RegionGrowing: normal angle (and curvature) between kNN neighbours
  kRegionGrowingRgb,  // pcl::RegionGrowingRGB: colour distance between radius neighbours
};

struct PclSegmentationSettings {
  PclSegmenter segmenter = PclSegmenter::kRegionGrowing;
  // RegionGrowing: neighbours searched per point, and the largest angle
  // between the normals of neighbours in one region [deg].
  int neighbours = 30;
  float smoothness_deg = 6.0f;
  // RegionGrowing: a point whose curvature is above this joins a region but
  // does not spread it; ≤ 0 turns the test off.
  float curvature_threshold = 0.0f;
  // RegionGrowingRGB: neighbour radius [m], the colour distance (8-bit RGB,
  // Euclidean) between neighbours in a region, and between regions merged
  // afterwards.
  float distance_m = 0.1f;
  // The defaults are the best of a sweep on the campus (docs/segmentation.md).
  float point_color_threshold = 8.0f;
  float region_color_threshold = 8.0f;
  // Smaller clusters are dropped (their points get no segment).
  int min_cluster_size = 10;
};

struct PclSegmentationResult {
  std::vector<std::int32_t> label;  // per pixel, row-major: segment index, −1 = none
  std::size_t segments = 0;
  double seconds = 0.0;  // search structure, normals input and extract()
};

// Segments the pixels where `usable` is non-zero (points in the scan frame;
// our normals and colours, the curvature 1 − confidence) with PCL.
PclSegmentationResult segment_with_pcl(const acquisition::Scan& scan,
                                       const acquisition::ScanGeometry& geometry,
                                       const std::vector<std::uint8_t>& usable,
                                       const PclSegmentationSettings& settings);

}  // namespace scanbench::bench

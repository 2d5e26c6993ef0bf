// PCL's organized-cloud and kNN normal estimators run on our scans.
//
// PCL's integral-image estimator (Holzer et al., "Adaptive neighborhood
// selection for real-time surface normal estimation from organized point
// cloud data using integral images", IROS 2012) was written for depth cameras:
// it reads the point's z as its depth, both for the depth-change edge test and
// for depth-dependent smoothing. A panoramic scan has no such axis (in the
// scan frame z is height), so those two features misfire here; the bench
// chooses its settings by measurement (see bench_geometry.cpp).
#include "bench/pcl_normals.hpp"

#include <pcl/console/print.h>
#include <pcl/features/integral_image_normal.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/memory.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/search/organized.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>

namespace scanbench::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;

template <typename Work>
double best_seconds(int repeats, Work&& work) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
    work();
    const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
    best = std::min(best, elapsed.count());
  }
  return best;
}

// width = columns, height = rows, NaN where no return; the sensor origin stays
// at (0, 0, 0), the scanner's position in its own frame.
Cloud::Ptr organized_cloud(const acquisition::Scan& scan) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  auto cloud = pcl::make_shared<Cloud>(scan.columns, scan.rows, pcl::PointXYZ(nan, nan, nan));
  cloud->is_dense = false;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      if (!scan.valid[scan.index(row, col)]) continue;
      const Eigen::Vector3f p = acquisition::point_in_scan(scan, row, col);
      cloud->at(col, row) = pcl::PointXYZ(p.x(), p.y(), p.z());
    }
  }
  return cloud;
}

// Feature::compute gives every estimator a neighbour search over its input,
// and on an organized cloud that is an OrganizedNeighbor, which fits a camera
// projection to the cloud. The integral-image estimator never searches, so
// the search is prepared here, outside the timed region, to keep PCL's time
// to the normals alone. The fit fails on a panorama ("not from a projective
// device") and says so on stderr; that message is silenced.
pcl::search::OrganizedNeighbor<pcl::PointXYZ>::Ptr prepared_organized_search(
    const Cloud::ConstPtr& cloud) {
  auto search = pcl::make_shared<pcl::search::OrganizedNeighbor<pcl::PointXYZ>>();
  const pcl::console::VERBOSITY_LEVEL level = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  search->setInputCloud(cloud);
  pcl::console::setVerbosityLevel(level);
  return search;
}

// Computes into a new cloud, then swaps it into `normals`; the previous
// run's cloud is freed here too, as a previous run's result is in ours.
template <typename Estimator>
void compute_fresh(Estimator& estimator, Normals& normals) {
  Normals fresh;
  estimator.compute(fresh);
  normals.swap(fresh);
}

// PCL marks a missing normal with NaN; we use the zero vector (ScanGeometry's
// sentinel) so both are compared the same way.
void store_normal(const pcl::Normal& n, std::size_t pixel, PclNormalResult& result) {
  const Eigen::Vector3f v(n.normal_x, n.normal_y, n.normal_z);
  if (!v.allFinite() || v.squaredNorm() < 1e-12f) return;
  result.normal[pixel] = v.normalized();
  ++result.normals;
}

PclNormalResult integral_image_normals(const acquisition::Scan& scan,
                                       const PclNormalSettings& settings) {
  const Cloud::Ptr cloud = organized_cloud(scan);
  const auto unused_search = prepared_organized_search(cloud);
  Normals normals;
  PclNormalResult result;
  // A fresh estimator and a fresh output per run: its integral images and
  // its normals are allocated and filled inside the timed region, as in a
  // one-shot use (and as compute_geometry allocates its own outputs).
  result.seconds = best_seconds(settings.repeats, [&] {
    pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> estimator;
    estimator.setNormalEstimationMethod(settings.method == PclNormalMethod::kIntegralCovariance
                                            ? estimator.COVARIANCE_MATRIX
                                            : estimator.AVERAGE_3D_GRADIENT);
    estimator.setMaxDepthChangeFactor(settings.max_depth_change_factor);
    estimator.setNormalSmoothingSize(settings.normal_smoothing_size);
    estimator.setDepthDependentSmoothing(settings.depth_dependent_smoothing);
    estimator.setViewPoint(0.0f, 0.0f, 0.0f);
    estimator.setSearchMethod(unused_search);
    estimator.setInputCloud(cloud);
    compute_fresh(estimator, normals);
  });
  result.normal.assign(scan.pixel_count(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < normals.size(); ++i) store_normal(normals[i], i, result);
  return result;
}

PclNormalResult knn_normals(const acquisition::Scan& scan, const PclNormalSettings& settings) {
  // The kd-tree holds the valid points only: NaNs have no place in it.
  auto cloud = pcl::make_shared<Cloud>();
  std::vector<std::size_t> pixel_of_point;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      if (!scan.valid[scan.index(row, col)]) continue;
      const Eigen::Vector3f p = acquisition::point_in_scan(scan, row, col);
      cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      pixel_of_point.push_back(scan.index(row, col));
    }
  }
  Normals normals;
  PclNormalResult result;
  result.seconds = best_seconds(settings.repeats, [&] {
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimator(
        static_cast<unsigned>(settings.threads));
    estimator.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    estimator.setKSearch(settings.k_neighbours);
    estimator.setInputCloud(cloud);
    estimator.setViewPoint(0.0f, 0.0f, 0.0f);
    compute_fresh(estimator, normals);
  });
  result.normal.assign(scan.pixel_count(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < normals.size(); ++i)
    store_normal(normals[i], pixel_of_point[i], result);
  return result;
}

}  // namespace

PclNormalResult estimate_pcl_normals(const acquisition::Scan& scan,
                                     const PclNormalSettings& settings) {
  assert(acquisition::check_consistency(scan).empty() && "inconsistent scan");
  assert(settings.repeats >= 1 && "at least one timed run");
  if (settings.method == PclNormalMethod::kKnnOmp) return knn_normals(scan, settings);
  return integral_image_normals(scan, settings);
}

}  // namespace scanbench::bench

// PCL adapter: FPFH + SampleConsensusPrerejective. PCL headers stay in this file.
#include "registration/feature_alignment.hpp"

#include <pcl/features/fpfh_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/sample_consensus_prerejective.h>
#include <pcl/search/kdtree.h>

#include <chrono>
#include <cstdlib>

#include "acquisition/parallel.hpp"
#include "acquisition/timing.hpp"
#include "registration/pcl_sample_cloud.hpp"

namespace scanbench::registration {

using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

struct FeatureCloud::Impl {
  Cloud::Ptr points = std::make_shared<Cloud>();
  Features::Ptr features = std::make_shared<Features>();
};

FeatureCloud::FeatureCloud(const SampleCloud& sample, const FeatureSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  impl_->points = to_pcl_cloud(sample);
  if (impl_->points->empty()) return;
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> estimator;
  estimator.setNumberOfThreads(static_cast<unsigned>(acquisition::worker_count(settings.threads)));
  estimator.setInputCloud(impl_->points);
  estimator.setInputNormals(impl_->points);
  estimator.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointNormal>>());
  estimator.setRadiusSearch(settings.feature_radius_m);
  estimator.compute(*impl_->features);
}

FeatureCloud::~FeatureCloud() = default;
FeatureCloud::FeatureCloud(FeatureCloud&&) noexcept = default;
FeatureCloud& FeatureCloud::operator=(FeatureCloud&&) noexcept = default;
std::size_t FeatureCloud::size() const {
  return impl_->points->size();
}

namespace {

// Clouds and their features, as PCL holds them.
struct Described {
  const Cloud::Ptr& points;
  const Features::Ptr& features;
};

FeatureAlignmentResult run_ransac(Described source, Described target,
                                  const FeatureSettings& settings) {
  FeatureAlignmentResult result;
  if (source.points->size() < 3 || target.points->size() < 3) {
    result.failure = "too few points with normals for features";
    return result;
  }
  pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> ransac;
  ransac.setInputSource(source.points);
  ransac.setSourceFeatures(source.features);
  ransac.setInputTarget(target.points);
  ransac.setTargetFeatures(target.features);
  ransac.setMaximumIterations(settings.max_iterations);
  ransac.setNumberOfSamples(3);
  ransac.setCorrespondenceRandomness(settings.correspondence_randomness);
  ransac.setSimilarityThreshold(static_cast<float>(settings.similarity));
  ransac.setMaxCorrespondenceDistance(settings.inlier_distance_m);
  ransac.setInlierFraction(static_cast<float>(settings.min_inlier_ratio));
  // PCL draws its samples with std::rand; seeding it makes runs repeatable.
  std::srand(static_cast<unsigned>(settings.seed));
  Cloud aligned;
  ransac.align(aligned);
  result.inliers = ransac.getInliers().size();
  result.inlier_ratio = static_cast<double>(result.inliers) / source.points->size();
  result.T_target_source.matrix() = ransac.getFinalTransformation().cast<double>();
  result.success = ransac.hasConverged() && result.inlier_ratio >= settings.min_inlier_ratio;
  if (!result.success) {
    result.failure =
        "no consistent feature matches (inlier ratio " + std::to_string(result.inlier_ratio) + ")";
  }
  return result;
}

}  // namespace

FeatureAlignmentResult align_features(const FeatureCloud& source, const FeatureCloud& target,
                                      const FeatureSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  FeatureAlignmentResult result =
      run_ransac({source.impl_->points, source.impl_->features},
                 {target.impl_->points, target.impl_->features}, settings);
  result.seconds = acquisition::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration

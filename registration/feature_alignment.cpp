// PCL adapter: FPFH features and their matching. PCL headers stay in this
// file; the hypotheses are ours (coarse_hypotheses.hpp).
#include "registration/feature_alignment.hpp"

#include <pcl/features/fpfh_omp.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <optional>

#include "core/parallel.hpp"
#include "core/timing.hpp"
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
  estimator.setNumberOfThreads(static_cast<unsigned>(core::worker_count(settings.threads)));
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

bool finite(const pcl::FPFHSignature33& feature) {
  return std::all_of(std::begin(feature.histogram), std::end(feature.histogram),
                     [](float bin) { return std::isfinite(bin); });
}

Eigen::Vector3f position(const pcl::PointNormal& p) {
  return {p.x, p.y, p.z};
}
Eigen::Vector3f normal(const pcl::PointNormal& p) {
  return {p.normal_x, p.normal_y, p.normal_z};
}

// Every source sample with each of the `neighbours` target samples whose
// features are nearest to its own, in source order.
std::vector<FeatureMatch> match_features(Described source, Described target,
                                         const FeatureSettings& settings) {
  pcl::KdTreeFLANN<pcl::FPFHSignature33> index;
  index.setInputCloud(target.features);
  const auto k = static_cast<std::size_t>(std::max(1, settings.neighbours));
  // Unit normals' vertical components differ by at most 2: no filter.
  const double max_dz = settings.levelled ? settings.max_normal_z_difference : 2.0;
  // Slot i·k + j holds the source sample i's j-th match, when it has one.
  std::vector<std::optional<FeatureMatch>> slots(source.points->size() * k);
  core::parallel_for_index(
      static_cast<int>(source.points->size()), settings.threads,
      [&](int i) {
        const pcl::FPFHSignature33& feature = (*source.features)[static_cast<std::size_t>(i)];
        if (!finite(feature)) return;
        std::vector<int> nearest(k);
        std::vector<float> distances(k);
        const int found = index.nearestKSearch(feature, static_cast<int>(k), nearest, distances);
        const pcl::PointNormal& s = (*source.points)[static_cast<std::size_t>(i)];
        for (int j = 0; j < found; ++j) {
          const pcl::PointNormal& t = (*target.points)[static_cast<std::size_t>(nearest[j])];
          if (std::abs(s.normal_z - t.normal_z) > max_dz) continue;
          slots[static_cast<std::size_t>(i) * k + static_cast<std::size_t>(j)] =
              FeatureMatch{position(s), normal(s), position(t), normal(t)};
        }
      },
      64);
  std::vector<FeatureMatch> matches;
  for (const std::optional<FeatureMatch>& slot : slots) {
    if (slot) matches.push_back(*slot);
  }
  return matches;
}

std::vector<PoseHypothesis> hypotheses_from(std::span<const FeatureMatch> matches,
                                            const FeatureSettings& settings) {
  if (settings.levelled) return levelled_hypotheses(matches, settings.hypotheses);
  return unlevelled_hypotheses(matches, settings.max_iterations, settings.similarity,
                               settings.hypotheses);
}

}  // namespace

FeatureAlignmentResult align_features(const FeatureCloud& source, const FeatureCloud& target,
                                      const FeatureSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  FeatureAlignmentResult result;
  const Described from{source.impl_->points, source.impl_->features};
  const Described to{target.impl_->points, target.impl_->features};
  if (from.points->size() < 3 || to.points->size() < 3) {
    result.failure = "too few points with normals for features";
  } else {
    const std::vector<FeatureMatch> matches = match_features(from, to, settings);
    result.matches = matches.size();
    for (PoseHypothesis& hypothesis : hypotheses_from(matches, settings)) {
      if (hypothesis.inliers >= settings.min_inliers) {
        result.hypotheses.push_back(std::move(hypothesis));
      }
    }
    if (result.hypotheses.empty()) {
      result.failure = "no pose agrees with " + std::to_string(settings.min_inliers) + " of the " +
                       std::to_string(matches.size()) + " feature matches";
    }
  }
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::registration

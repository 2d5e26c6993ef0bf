// Automatic coarse registration: FPFH features (Rusu et al. 2009) matched
// with prerejective RANSAC (Buch et al. 2013), through PCL. No pose guess is
// needed; the result counts only when enough matched points agree.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

struct FeatureSettings {
  // The clouds features are computed on: one sample per voxel of this edge.
  SampleSettings sample{0.5, 6000};
  double feature_radius_m = 1.5;  // FPFH support radius
  // RANSAC: a hypothesis from 3 feature matches, each drawn among the
  // `correspondence_randomness` nearest features; pre-rejected when the
  // edge lengths of the two triangles differ by more than 1 − similarity.
  int max_iterations = 20000;
  int correspondence_randomness = 3;
  double similarity = 0.9;
  double inlier_distance_m = 1.0;  // a moved source point this near a target point is an inlier
  // Accepted only when at least this share of the source points are inliers.
  double min_inlier_ratio = 0.2;
  std::uint64_t seed = 1;  // RANSAC draws; same seed, same result
  int threads = 0;         // feature computation; 0 = all cores
};

struct FeatureAlignmentResult {
  bool success = false;  // enough inliers; else T_target_source is meaningless
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  std::size_t inliers = 0;
  double inlier_ratio = 0.0;  // inliers / source points
  double seconds = 0.0;
  std::string failure;  // why success is false; empty on success
};

// The features of one scan's sample, computed once and reused for every pair.
class FeatureCloud {
 public:
  FeatureCloud(const SampleCloud& sample, const FeatureSettings& settings);
  ~FeatureCloud();
  FeatureCloud(FeatureCloud&&) noexcept;
  FeatureCloud& operator=(FeatureCloud&&) noexcept;
  std::size_t size() const;

 private:
  friend FeatureAlignmentResult align_features(const FeatureCloud&, const FeatureCloud&,
                                               const FeatureSettings&);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Aligns the source features to the target features.
FeatureAlignmentResult align_features(const FeatureCloud& source, const FeatureCloud& target,
                                      const FeatureSettings& settings);

}  // namespace scanbench::registration

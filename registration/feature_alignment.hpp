// Automatic coarse registration: FPFH features (Rusu et al. 2009, fpfh.hpp)
// matched between two scans, and pose hypotheses drawn from the matches
// by RANSAC. No pose guess is needed. A hypothesis is only a candidate: the
// pipeline (register_scans.cpp) keeps one only after ICP from it lands most
// of the scan on the target's surfaces and none in its free space.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "registration/coarse_hypotheses.hpp"
#include "registration/fpfh.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

struct FeatureSettings {
  // The clouds features are computed on: one sample per voxel of this edge.
  SampleSettings sample{0.5, 30000};
  double feature_radius_m = 1.5;  // FPFH support radius
  int neighbours = 3;             // target features matched to each source feature
  // Scans from a levelled scanner (scan z axis up, within a few degrees):
  // hypotheses from one match each (coarse_hypotheses.hpp), and matches
  // whose normals differ by more than max_normal_z_difference in their
  // vertical component are dropped (a heading turn leaves it unchanged).
  // Otherwise each hypothesis comes from three matches
  // (unlevelled_hypotheses).
  bool levelled = true;
  double max_normal_z_difference = 0.15;
  HypothesisSettings hypotheses;  // both kinds; max_vertical_normal: levelled only
  // Not levelled: max_iterations draws of three matches; a draw is
  // pre-rejected when the edge lengths of its two triangles differ by more
  // than 1 − similarity.
  int max_iterations = 20000;
  double similarity = 0.9;
  // A hypothesis needs at least this many matches within the inlier distance.
  std::size_t min_inliers = 10;
  // Verification (register_scans.cpp): ICP runs from the hypotheses with
  // the most inliers and from those that put the largest share of a thinned
  // sample (screening_samples) on the target's surfaces, less the share in
  // its free space.
  std::size_t verify_by_inliers = 6;
  std::size_t verify_by_overlap = 6;
  std::size_t screening_samples = 3000;
  int threads = 0;  // feature computation and matching; 0 = all cores
};

struct FeatureAlignmentResult {
  // Distinct poses with at least min_inliers, most inliers first; empty on
  // failure.
  std::vector<PoseHypothesis> hypotheses;
  std::size_t matches = 0;  // feature matches the hypotheses were drawn from
  double seconds = 0.0;
  std::string failure;  // why hypotheses is empty
};

// The features of one scan's sample, computed once and reused for every pair.
class FeatureCloud {
 public:
  FeatureCloud(const SampleCloud& sample, const FeatureSettings& settings);
  std::size_t size() const { return sample_.size(); }
  const SampleCloud& sample() const { return sample_; }
  const FpfhResult& fpfh() const { return fpfh_; }

 private:
  SampleCloud sample_;
  FpfhResult fpfh_;
};

// Pose hypotheses taking the source scan's frame to the target's.
FeatureAlignmentResult align_features(const FeatureCloud& source, const FeatureCloud& target,
                                      const FeatureSettings& settings);

}  // namespace scanbench::registration

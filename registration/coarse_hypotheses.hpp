// Pose hypotheses from feature matches, for scans taken by a levelled
// scanner: RANSAC whose minimal sample is one match of oriented points.
//
// Terrestrial scanners are levelled on site (a tilt compensator or a bubble
// level), so two scans differ by a heading and a translation, up to a tilt of
// a few degrees. One matched point with a non-vertical normal then fixes the
// heading (the angle between the two normals' horizontal parts) and the
// translation: a hypothesis from a single match, where a general rigid pose
// needs three (RANSAC, Fischler and Bolles 1981, with the smallest sample
// the motion model allows). Feature matches on façades and ground are
// mostly wrong (often 99 %): a one-match sample is right about 1 time in
// 100, a three-match sample 1 time in a million.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace scanbench::registration {

// A source sample and a target sample whose features are alike, each in its
// own scan frame.
struct FeatureMatch {
  Eigen::Vector3f source_point;
  Eigen::Vector3f source_normal;  // unit
  Eigen::Vector3f target_point;
  Eigen::Vector3f target_normal;  // unit
};

struct HypothesisSettings {
  int draws = 3000;                // matches drawn, one hypothesis each
  double inlier_distance_m = 0.5;  // a moved source point this near its match agrees
  // Only matches whose normals are at most this vertical (|n_z|) are drawn:
  // a horizontal surface says nothing about the heading.
  double max_vertical_normal = 0.7;
  // Draws are scored on at most this many matches (spread evenly); the kept
  // hypotheses are then refined and recounted on all of them.
  std::size_t scoring_matches = 8000;
  std::size_t keep = 40;  // distinct hypotheses returned, most inliers first
  // Two hypotheses are the same when they differ by less than this.
  double distinct_rotation_rad = 0.05;
  double distinct_translation_m = 1.0;
  std::uint64_t seed = 1;  // same seed, same hypotheses
};

struct PoseHypothesis {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  std::size_t inliers = 0;  // matches within inlier_distance_m at this pose
};

// The matches within `distance_m` at pose T.
std::size_t count_inliers(std::span<const FeatureMatch> matches, const Eigen::Isometry3f& T,
                          double distance_m);

// Refits T in all six degrees of freedom to the matches it explains (a
// rigid least-squares fit, repeated with the inlier distance shrinking from
// twice `distance_m` to `distance_m`; the local optimisation of LO-RANSAC,
// Chum, Matas and Kittler 2003): this also recovers the tilt that the
// levelled hypotheses leave out. Returns the refit with its inlier count, or
// T with its own when the refit explains fewer matches.
PoseHypothesis refine_hypothesis(std::span<const FeatureMatch> matches, const Eigen::Isometry3d& T,
                                 double distance_m);

// RANSAC over one-match samples; every kept hypothesis refined
// (refine_hypothesis). Distinct poses, most inliers first; empty when no
// match has a usable normal.
std::vector<PoseHypothesis> levelled_hypotheses(std::span<const FeatureMatch> matches,
                                                const HypothesisSettings& settings);

// RANSAC over three-match samples, for scans of a scanner that was not
// levelled: `draws` random triples of matches; a triple whose source and
// target triangles are not alike (edge lengths within 1 − similarity of the
// longer; the pre-rejection of Buch et al. 2013) is dropped unfitted, the
// others are fitted (fit_rigid) and scored. Kept and refined as
// levelled_hypotheses does. Same seed, same hypotheses.
std::vector<PoseHypothesis> unlevelled_hypotheses(std::span<const FeatureMatch> matches, int draws,
                                                  double similarity,
                                                  const HypothesisSettings& settings);

// Keeps the first of every group of hypotheses closer than the settings'
// distinct thresholds, in order.
std::vector<PoseHypothesis> distinct_hypotheses(std::vector<PoseHypothesis> hypotheses,
                                                const HypothesisSettings& settings);

}  // namespace scanbench::registration

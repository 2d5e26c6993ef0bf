#include "registration/coarse_hypotheses.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "registration/pose_parameters.hpp"
#include "registration/rigid_fit.hpp"

namespace scanbench::registration {
namespace {

// The levelled pose that carries the match's source point onto its target
// point and the horizontal part of its normal onto the target's.
Eigen::Isometry3f pose_from_match(const FeatureMatch& match) {
  const float heading = std::atan2(match.target_normal.y(), match.target_normal.x()) -
                        std::atan2(match.source_normal.y(), match.source_normal.x());
  Eigen::Isometry3f T = Eigen::Isometry3f::Identity();
  T.linear() = Eigen::AngleAxisf(heading, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  T.translation() = match.target_point - T.linear() * match.source_point;
  return T;
}

bool more_inliers(const PoseHypothesis& a, const PoseHypothesis& b) {
  return a.inliers > b.inliers;
}

// Every k-th match, at most settings.scoring_matches: what draws are scored on.
std::vector<FeatureMatch> scoring_subset(std::span<const FeatureMatch> matches,
                                         const HypothesisSettings& settings) {
  const std::size_t stride =
      std::max<std::size_t>(1, (matches.size() + settings.scoring_matches - 1) /
                                   std::max<std::size_t>(1, settings.scoring_matches));
  std::vector<FeatureMatch> scoring;
  for (std::size_t i = 0; i < matches.size(); i += stride) scoring.push_back(matches[i]);
  return scoring;
}

// The best distinct drawn hypotheses, each refined on all matches.
std::vector<PoseHypothesis> keep_and_refine(std::vector<PoseHypothesis> drawn,
                                            std::span<const FeatureMatch> matches,
                                            const HypothesisSettings& settings) {
  std::stable_sort(drawn.begin(), drawn.end(), more_inliers);
  std::vector<PoseHypothesis> kept = distinct_hypotheses(std::move(drawn), settings);
  for (PoseHypothesis& hypothesis : kept) {
    hypothesis = refine_hypothesis(matches, hypothesis.T_target_source, settings.inlier_distance_m);
  }
  // Refinement can bring two hypotheses to the same pose.
  std::stable_sort(kept.begin(), kept.end(), more_inliers);
  return distinct_hypotheses(std::move(kept), settings);
}

// True when the triangles of the three matches' source and target points
// have edges of alike lengths (within 1 − similarity of the longer): a
// rigid motion keeps lengths, so other triples cannot be all right.
bool alike_triangles(const FeatureMatch* m[3], double similarity) {
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3;
    const float source = (m[a]->source_point - m[b]->source_point).norm();
    const float target = (m[a]->target_point - m[b]->target_point).norm();
    const float longer = std::max(source, target);
    if (longer <= 0.0f || std::abs(source - target) > (1.0 - similarity) * longer) return false;
  }
  return true;
}

}  // namespace

std::size_t count_inliers(std::span<const FeatureMatch> matches, const Eigen::Isometry3f& T,
                          double distance_m) {
  const auto squared = static_cast<float>(distance_m * distance_m);
  std::size_t inliers = 0;
  for (const FeatureMatch& match : matches) {
    inliers += (T * match.source_point - match.target_point).squaredNorm() < squared;
  }
  return inliers;
}

PoseHypothesis refine_hypothesis(std::span<const FeatureMatch> matches, const Eigen::Isometry3d& T,
                                 double distance_m) {
  const PoseHypothesis given{T, count_inliers(matches, T.cast<float>(), distance_m)};
  PoseHypothesis refined{T, 0};
  std::vector<PointPair> pairs;
  for (const double scale : {2.0, 1.5, 1.0}) {
    const auto squared = static_cast<float>(scale * scale * distance_m * distance_m);
    const Eigen::Isometry3f Tf = refined.T_target_source.cast<float>();
    pairs.clear();
    for (const FeatureMatch& match : matches) {
      if ((Tf * match.source_point - match.target_point).squaredNorm() < squared) {
        pairs.push_back({match.source_point.cast<double>(), match.target_point.cast<double>()});
      }
    }
    const RigidFitResult fit = fit_rigid(pairs);
    if (fit.valid) refined.T_target_source = fit.T_target_source;
  }
  refined.inliers = count_inliers(matches, refined.T_target_source.cast<float>(), distance_m);
  return refined.inliers >= given.inliers ? refined : given;
}

std::vector<PoseHypothesis> distinct_hypotheses(std::vector<PoseHypothesis> hypotheses,
                                                const HypothesisSettings& settings) {
  std::vector<PoseHypothesis> kept;
  for (PoseHypothesis& candidate : hypotheses) {
    if (kept.size() == settings.keep) break;
    const bool repeated = std::any_of(kept.begin(), kept.end(), [&](const PoseHypothesis& k) {
      const auto [rotation, translation] =
          pose_change(k.T_target_source, candidate.T_target_source);
      return rotation < settings.distinct_rotation_rad &&
             translation < settings.distinct_translation_m;
    });
    if (!repeated) kept.push_back(std::move(candidate));
  }
  return kept;
}

std::vector<PoseHypothesis> levelled_hypotheses(std::span<const FeatureMatch> matches,
                                                const HypothesisSettings& settings) {
  const auto max_vertical = static_cast<float>(settings.max_vertical_normal);
  std::vector<std::size_t> drawable;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (std::abs(matches[i].source_normal.z()) <= max_vertical &&
        std::abs(matches[i].target_normal.z()) <= max_vertical) {
      drawable.push_back(i);
    }
  }
  if (drawable.empty() || settings.draws <= 0) return {};

  const std::vector<FeatureMatch> scoring = scoring_subset(matches, settings);
  std::mt19937_64 random(settings.seed);
  std::vector<PoseHypothesis> drawn;
  drawn.reserve(static_cast<std::size_t>(settings.draws));
  for (int draw = 0; draw < settings.draws; ++draw) {
    const FeatureMatch& sample = matches[drawable[random() % drawable.size()]];
    const Eigen::Isometry3f T = pose_from_match(sample);
    drawn.push_back({T.cast<double>(), count_inliers(scoring, T, settings.inlier_distance_m)});
  }
  return keep_and_refine(std::move(drawn), matches, settings);
}

std::vector<PoseHypothesis> unlevelled_hypotheses(std::span<const FeatureMatch> matches, int draws,
                                                  double similarity,
                                                  const HypothesisSettings& settings) {
  if (matches.size() < 3 || draws <= 0) return {};
  const std::vector<FeatureMatch> scoring = scoring_subset(matches, settings);
  std::mt19937_64 random(settings.seed);
  std::vector<PoseHypothesis> drawn;
  for (int draw = 0; draw < draws; ++draw) {
    const FeatureMatch* sample[3];
    for (const FeatureMatch*& m : sample) m = &matches[random() % matches.size()];
    if (sample[0] == sample[1] || sample[1] == sample[2] || sample[0] == sample[2]) continue;
    if (!alike_triangles(sample, similarity)) continue;
    std::vector<PointPair> pairs;
    for (const FeatureMatch* m : sample) {
      pairs.push_back({m->source_point.cast<double>(), m->target_point.cast<double>()});
    }
    const RigidFitResult fit = fit_rigid(pairs);
    if (!fit.valid) continue;
    const Eigen::Isometry3f T = fit.T_target_source.cast<float>();
    drawn.push_back({fit.T_target_source, count_inliers(scoring, T, settings.inlier_distance_m)});
  }
  return keep_and_refine(std::move(drawn), matches, settings);
}

}  // namespace scanbench::registration

// Pose hypotheses from one oriented match each: a known pose recovered from
// matches that are mostly wrong, the tilt recovered by the refinement,
// matches without a usable normal, repeatability and de-duplication.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include "acquisition/simulation/random.hpp"
#include "registration/coarse_hypotheses.hpp"
#include "registration/pose_parameters.hpp"
#include "support/test_support.hpp"

namespace scanbench::registration {
namespace {

using scanbench::test::kDeg;

Eigen::Isometry3d levelled_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(127.0 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(14.0, -6.5, 0.3);
  return T;
}

// The levelled pose with the source scanner tilted by 2° about a horizontal axis.
Eigen::Isometry3d tilted_pose() {
  Eigen::Isometry3d T = levelled_pose();
  T.rotate(Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d(1.0, 1.0, 0.0).normalized()));
  return T;
}

Eigen::Vector3f random_point(acquisition::sim::Random& random) {
  return Eigen::Vector3f(static_cast<float>(random.uniform(-30.0, 30.0)),
                         static_cast<float>(random.uniform(-30.0, 30.0)),
                         static_cast<float>(random.uniform(-2.0, 8.0)));
}

// A normal of a wall or, one time in three, of the ground.
Eigen::Vector3f random_normal(acquisition::sim::Random& random) {
  if (random.uniform(0.0, 1.0) < 1.0 / 3.0) return Eigen::Vector3f::UnitZ();
  const double heading = random.uniform(-std::numbers::pi, std::numbers::pi);
  return Eigen::Vector3f(static_cast<float>(std::cos(heading)),
                         static_cast<float>(std::sin(heading)),
                         static_cast<float>(random.uniform(-0.3, 0.3)))
      .normalized();
}

// `correct` matches that T explains exactly, then `wrong` ones pairing
// unrelated points and normals.
std::vector<FeatureMatch> matches_of(const Eigen::Isometry3d& T, int correct, int wrong,
                                     std::uint64_t seed) {
  acquisition::sim::Random random(seed);
  const Eigen::Isometry3f Tf = T.cast<float>();
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < correct; ++i) {
    const Eigen::Vector3f p = random_point(random);
    const Eigen::Vector3f n = random_normal(random);
    matches.push_back({p, n, Tf * p, Tf.linear() * n});
  }
  for (int i = 0; i < wrong; ++i) {
    matches.push_back(
        {random_point(random), random_normal(random), random_point(random), random_normal(random)});
  }
  return matches;
}

void expect_pose(const Eigen::Isometry3d& expected, const PoseHypothesis& actual,
                 double max_rotation_deg, double max_translation_m) {
  const auto [rotation, translation] = pose_change(expected, actual.T_target_source);
  EXPECT_LT(rotation / kDeg, max_rotation_deg);
  EXPECT_LT(translation, max_translation_m);
}

TEST(CoarseHypotheses, FindsALevelledPoseAmongNinetyEightPercentWrongMatches) {
  const std::vector<FeatureMatch> matches = matches_of(levelled_pose(), 100, 4900, 1);
  const std::vector<PoseHypothesis> hypotheses = levelled_hypotheses(matches, {});
  ASSERT_FALSE(hypotheses.empty());
  // The refinement fits the correct matches exactly (float points).
  expect_pose(levelled_pose(), hypotheses[0], 1e-3, 1e-4);
  EXPECT_GE(hypotheses[0].inliers, 100u);
  EXPECT_LE(hypotheses[0].inliers, 105u);  // a wrong match may land near by chance
  ASSERT_GT(hypotheses.size(), 1u);
  EXPECT_LT(hypotheses[1].inliers, 30u);  // nothing else comes close
}

TEST(CoarseHypotheses, TheRefinementRecoversATiltTheHypothesesLeaveOut) {
  const std::vector<FeatureMatch> matches = matches_of(tilted_pose(), 200, 3800, 2);
  const std::vector<PoseHypothesis> hypotheses = levelled_hypotheses(matches, {});
  ASSERT_FALSE(hypotheses.empty());
  expect_pose(tilted_pose(), hypotheses[0], 1e-3, 1e-4);
  EXPECT_GE(hypotheses[0].inliers, 200u);
  // No levelled pose explains them all: the best one, with the true heading
  // and translation, loses the points tilted more than 0.5 m away.
  EXPECT_LT(count_inliers(matches, levelled_pose().cast<float>(), 0.5), 150u);
}

TEST(CoarseHypotheses, MatchesOnHorizontalSurfacesOnlyGiveNoHypothesis) {
  std::vector<FeatureMatch> matches = matches_of(levelled_pose(), 100, 100, 3);
  for (FeatureMatch& match : matches) {
    match.source_normal = Eigen::Vector3f::UnitZ();
    match.target_normal = Eigen::Vector3f::UnitZ();
  }
  EXPECT_TRUE(levelled_hypotheses(matches, {}).empty());
  EXPECT_TRUE(levelled_hypotheses({}, {}).empty());
}

TEST(CoarseHypotheses, TheSameSeedGivesTheSameHypotheses) {
  const std::vector<FeatureMatch> matches = matches_of(levelled_pose(), 50, 2000, 4);
  HypothesisSettings settings;
  settings.draws = 300;
  const std::vector<PoseHypothesis> a = levelled_hypotheses(matches, settings);
  const std::vector<PoseHypothesis> b = levelled_hypotheses(matches, settings);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].inliers, b[i].inliers);
    EXPECT_TRUE(a[i].T_target_source.isApprox(b[i].T_target_source, 0.0));
  }
  // Another seed draws other matches: the weaker hypotheses differ.
  settings.seed = 2;
  const std::vector<PoseHypothesis> c = levelled_hypotheses(matches, settings);
  bool differs = c.size() != a.size();
  for (std::size_t i = 0; !differs && i < a.size(); ++i) {
    differs = !a[i].T_target_source.isApprox(c[i].T_target_source, 0.0);
  }
  EXPECT_TRUE(differs);
}

// A general (tilted, turned) pose, which no levelled hypothesis explains.
Eigen::Isometry3d general_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(35.0 * kDeg, Eigen::Vector3d(0.3, -0.5, 1.0).normalized())
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(-3.0, 8.0, 1.2);
  return T;
}

TEST(UnlevelledHypotheses, FindAGeneralPoseAmongMostlyWrongMatches) {
  // A third right: one triple in 27 is all right, so 2000 draws find it.
  const std::vector<FeatureMatch> matches = matches_of(general_pose(), 300, 600, 5);
  const std::vector<PoseHypothesis> hypotheses = unlevelled_hypotheses(matches, 2000, 0.9, {});
  ASSERT_FALSE(hypotheses.empty());
  expect_pose(general_pose(), hypotheses[0], 1e-3, 1e-4);
  EXPECT_GE(hypotheses[0].inliers, 300u);
  EXPECT_LE(hypotheses[0].inliers, 310u);  // a wrong match may land near by chance
}

TEST(UnlevelledHypotheses, PreRejectionDropsTriplesOfUnlikeTriangles) {
  // Only wrong matches: with similarity 1 (edge lengths must agree exactly)
  // no triple of unrelated points survives to be fitted.
  const std::vector<FeatureMatch> wrong = matches_of(general_pose(), 0, 500, 6);
  EXPECT_TRUE(unlevelled_hypotheses(wrong, 2000, 1.0, {}).empty());
  EXPECT_FALSE(unlevelled_hypotheses(wrong, 2000, 0.0, {}).empty());
}

TEST(UnlevelledHypotheses, TooFewMatchesGiveNoneAndTheSameSeedTheSameOnes) {
  const std::vector<FeatureMatch> matches = matches_of(general_pose(), 30, 300, 7);
  EXPECT_TRUE(unlevelled_hypotheses(std::span(matches).first(2), 100, 0.9, {}).empty());
  EXPECT_TRUE(unlevelled_hypotheses(matches, 0, 0.9, {}).empty());
  const std::vector<PoseHypothesis> a = unlevelled_hypotheses(matches, 500, 0.9, {});
  const std::vector<PoseHypothesis> b = unlevelled_hypotheses(matches, 500, 0.9, {});
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].inliers, b[i].inliers);
    EXPECT_TRUE(a[i].T_target_source.isApprox(b[i].T_target_source, 0.0));
  }
}

TEST(CoarseHypotheses, NearlyEqualPosesCountOnce) {
  HypothesisSettings settings;
  settings.keep = 10;
  Eigen::Isometry3d near = levelled_pose();
  near.translate(Eigen::Vector3d(0.3, 0.0, 0.0));  // under distinct_translation_m
  Eigen::Isometry3d far = levelled_pose();
  far.translate(Eigen::Vector3d(3.0, 0.0, 0.0));
  const std::vector<PoseHypothesis> kept =
      distinct_hypotheses({{levelled_pose(), 9}, {near, 8}, {far, 7}}, settings);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0].inliers, 9u);
  EXPECT_EQ(kept[1].inliers, 7u);
  settings.keep = 1;
  EXPECT_EQ(distinct_hypotheses({{levelled_pose(), 9}, {far, 7}}, settings).size(), 1u);
}

TEST(CoarseHypotheses, CountInliersUsesTheDistance) {
  const std::vector<FeatureMatch> matches = matches_of(levelled_pose(), 20, 0, 5);
  Eigen::Isometry3f off = levelled_pose().cast<float>();
  off.pretranslate(Eigen::Vector3f(0.4f, 0.0f, 0.0f));
  EXPECT_EQ(count_inliers(matches, off, 0.5), 20u);
  EXPECT_EQ(count_inliers(matches, off, 0.3), 0u);
}

}  // namespace
}  // namespace scanbench::registration

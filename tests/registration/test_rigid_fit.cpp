// Closed-form rigid fit of point pairs: exact recovery, noise, degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "acquisition/simulation/random.hpp"
#include "registration/pose_parameters.hpp"
#include "registration/rigid_fit.hpp"
#include "support/test_support.hpp"

namespace scanbench::registration {
namespace {

using scanbench::test::kDeg;

Eigen::Isometry3d known_transform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(37.0 * kDeg, Eigen::Vector3d(0.2, -0.5, 1.0).normalized())
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(12.5, -3.25, 1.75);
  return T;
}

std::vector<PointPair> pairs_of(const std::vector<Eigen::Vector3d>& sources,
                                const Eigen::Isometry3d& T) {
  std::vector<PointPair> pairs;
  for (const Eigen::Vector3d& s : sources) pairs.push_back({s, T * s});
  return pairs;
}

void expect_same_pose(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& actual,
                      double max_rotation_deg, double max_translation_m) {
  const auto [rotation, translation] = pose_change(expected, actual);
  EXPECT_LT(rotation / kDeg, max_rotation_deg);
  EXPECT_LT(translation, max_translation_m);
}

TEST(RigidFit, RecoversAKnownTransformFromThreePairs) {
  const Eigen::Isometry3d T = known_transform();
  const std::vector<PointPair> pairs =
      pairs_of({{0.0, 0.0, 0.0}, {4.0, 0.5, 0.0}, {1.0, 3.0, 2.0}}, T);
  const RigidFitResult fit = fit_rigid(pairs);
  ASSERT_TRUE(fit.valid);
  EXPECT_EQ(fit.pairs, 3u);
  expect_same_pose(T, fit.T_target_source, 1e-9, 1e-9);
  EXPECT_LT(fit.rms_m, 1e-9);
  EXPECT_LT(fit.max_residual_m, 1e-9);
}

TEST(RigidFit, RecoversAKnownTransformFromTenPairs) {
  const Eigen::Isometry3d T = known_transform();
  acquisition::sim::Random random(42);
  std::vector<Eigen::Vector3d> sources;
  for (int i = 0; i < 10; ++i) {
    sources.emplace_back(random.uniform(-20.0, 20.0), random.uniform(-20.0, 20.0),
                         random.uniform(-2.0, 8.0));
  }
  const RigidFitResult fit = fit_rigid(pairs_of(sources, T));
  ASSERT_TRUE(fit.valid);
  EXPECT_EQ(fit.pairs, 10u);
  expect_same_pose(T, fit.T_target_source, 1e-9, 1e-9);
  EXPECT_LT(fit.rms_m, 1e-9);
  EXPECT_NEAR(fit.T_target_source.linear().determinant(), 1.0, 1e-12);
}

TEST(RigidFit, NoisyPairsGiveAnRmsNearTheNoise) {
  // 200 pairs over a 40 m scene, 1 cm Gaussian noise per coordinate on the
  // target: the residual of a point is about √3 · 1 cm, minus the 6 degrees of
  // freedom the fit absorbs; the pose is off by well under a millimetre.
  const Eigen::Isometry3d T = known_transform();
  constexpr double kSigma = 0.01;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    acquisition::sim::Random random(seed);
    std::vector<PointPair> pairs;
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d s(random.uniform(-20.0, 20.0), random.uniform(-20.0, 20.0),
                              random.uniform(-2.0, 8.0));
      const Eigen::Vector3d noise(random.normal(0.0, kSigma), random.normal(0.0, kSigma),
                                  random.normal(0.0, kSigma));
      pairs.push_back({s, T * s + noise});
    }
    const RigidFitResult fit = fit_rigid(pairs);
    ASSERT_TRUE(fit.valid) << seed;
    const double expected_rms = std::sqrt(3.0 * (200.0 - 2.0) / 200.0) * kSigma;
    EXPECT_NEAR(fit.rms_m, expected_rms, 0.15 * expected_rms) << seed;
    EXPECT_GT(fit.max_residual_m, fit.rms_m) << seed;
    EXPECT_LT(fit.max_residual_m, 6.0 * kSigma) << seed;
    expect_same_pose(T, fit.T_target_source, 0.01, 0.005);
  }
}

TEST(RigidFit, FewerThanThreePairsAreInvalid) {
  const Eigen::Isometry3d T = known_transform();
  EXPECT_FALSE(fit_rigid({}).valid);
  const std::vector<PointPair> one = pairs_of({{1.0, 2.0, 3.0}}, T);
  EXPECT_FALSE(fit_rigid(one).valid);
  const std::vector<PointPair> two = pairs_of({{1.0, 2.0, 3.0}, {-4.0, 0.0, 1.0}}, T);
  const RigidFitResult fit = fit_rigid(two);
  EXPECT_FALSE(fit.valid);
  EXPECT_EQ(fit.pairs, 2u);
}

TEST(RigidFit, CollinearPointsAreInvalid) {
  const Eigen::Isometry3d T = known_transform();
  const Eigen::Vector3d a(1.0, 2.0, 0.5);
  const Eigen::Vector3d d = Eigen::Vector3d(3.0, -1.0, 0.25).normalized();
  std::vector<Eigen::Vector3d> line;
  for (double t : {0.0, 1.5, 4.0, 10.0, 25.0}) line.push_back(a + t * d);
  EXPECT_FALSE(fit_rigid(pairs_of(line, T)).valid);
  // Three copies of one point, and one point repeated with another.
  EXPECT_FALSE(fit_rigid(pairs_of({a, a, a}, T)).valid);
  EXPECT_FALSE(fit_rigid(pairs_of({a, a, a + d}, T)).valid);
  // One point off the line makes the fit determined again.
  line.push_back(a + Eigen::Vector3d(0.0, 0.0, 1.0));
  const RigidFitResult fit = fit_rigid(pairs_of(line, T));
  ASSERT_TRUE(fit.valid);
  expect_same_pose(T, fit.T_target_source, 1e-8, 1e-8);
}

TEST(RigidFit, NeverReturnsAReflection) {
  // Targets mirrored in a plane: no rotation maps the sources onto them, and
  // the best rotation must still be a rotation (det +1), not the mirror.
  acquisition::sim::Random random(7);
  const Eigen::Matrix3d mirror = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<PointPair> pairs;
    const int count = 3 + trial % 6;
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3d s(random.uniform(-5.0, 5.0), random.uniform(-5.0, 5.0),
                              random.uniform(-5.0, 5.0));
      pairs.push_back({s, known_transform() * (mirror * s)});
    }
    const RigidFitResult fit = fit_rigid(pairs);
    ASSERT_TRUE(fit.valid) << trial;
    const Eigen::Matrix3d R = fit.T_target_source.linear();
    EXPECT_NEAR(R.determinant(), 1.0, 1e-9) << trial;
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-9)
        << trial;
    if (count > 3) {
      EXPECT_GT(fit.rms_m, 1e-3) << trial;  // a mirror cannot be fitted
    }
  }
  // Planar points mirrored across their own plane: a rotation of 180° about
  // an in-plane axis does map them exactly; still a rotation.
  std::vector<PointPair> planar;
  for (const Eigen::Vector3d& s : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 0, 0),
                                   Eigen::Vector3d(0, 2, 0), Eigen::Vector3d(-1, 4, 0)}) {
    planar.push_back({s, Eigen::Vector3d(s.x(), -s.y(), 0.0)});
  }
  const RigidFitResult fit = fit_rigid(planar);
  ASSERT_TRUE(fit.valid);
  EXPECT_NEAR(fit.T_target_source.linear().determinant(), 1.0, 1e-9);
  EXPECT_LT(fit.rms_m, 1e-9);
}

}  // namespace
}  // namespace scanbench::registration

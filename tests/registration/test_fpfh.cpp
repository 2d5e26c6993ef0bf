// FPFH (registration/fpfh.cpp) on tiny hand-built clouds: the exact
// histogram of a plane, no feature without neighbours, the same features
// after a rigid motion and on any thread count, and different features for
// different shapes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "registration/fpfh.hpp"

namespace scanbench::registration {
namespace {

// A 9 × 9 patch of the plane z = 0 at 1/8 m spacing (exact in float), its
// normals up, and one more point far from it.
SampleCloud plane_and_a_loner() {
  SampleCloud cloud;
  for (int i = 0; i < 9; ++i) {
    for (int j = 0; j < 9; ++j) {
      cloud.points.emplace_back(0.125f * static_cast<float>(i), 0.125f * static_cast<float>(j),
                                0.0f);
      cloud.normals.emplace_back(0.0f, 0.0f, 1.0f);
    }
  }
  cloud.points.emplace_back(50.0f, 50.0f, 0.0f);
  cloud.normals.emplace_back(0.0f, 0.0f, 1.0f);
  cloud.pixels.assign(cloud.points.size(), 0);
  return cloud;
}

// Half a sphere of radius 1 m around the origin, normals outward.
SampleCloud dome() {
  SampleCloud cloud;
  for (int a = 0; a < 24; ++a) {
    for (int e = 1; e < 8; ++e) {
      const double az = a * 2.0 * std::numbers::pi / 24.0, el = e * 0.5 * std::numbers::pi / 8.0;
      const Eigen::Vector3f n(static_cast<float>(std::cos(el) * std::cos(az)),
                              static_cast<float>(std::cos(el) * std::sin(az)),
                              static_cast<float>(std::sin(el)));
      cloud.points.push_back(n);
      cloud.normals.push_back(n);
    }
  }
  cloud.pixels.assign(cloud.points.size(), 0);
  return cloud;
}

TEST(Fpfh, APlaneGivesTheMiddleBinOfEachAngle) {
  // Any pair on a plane with equal normals: φ = 0, α = 0, θ = 0, each in
  // bin 5 of 11, so each histogram is 100 there.
  const FpfhResult result = compute_fpfh(plane_and_a_loner(), {0.3, 1});
  for (std::size_t i = 0; i + 1 < result.features.size(); ++i) {
    ASSERT_EQ(result.described[i], 1) << i;
    for (int b = 0; b < 33; ++b) {
      EXPECT_FLOAT_EQ(result.features[i][b], b % 11 == 5 ? 100.0f : 0.0f) << i << " bin " << b;
    }
  }
}

TEST(Fpfh, APointWithoutNeighboursHasNoFeature) {
  const FpfhResult result = compute_fpfh(plane_and_a_loner(), {0.3, 1});
  EXPECT_EQ(result.described.back(), 0);
  for (const float bin : result.features.back()) EXPECT_EQ(bin, 0.0f);
}

TEST(Fpfh, FeaturesDoNotChangeUnderARigidMotionOrTheThreadCount) {
  // A quarter turn about z and a whole-metre shift move the dyadic points
  // and their normals exactly: the features must be identical.
  SampleCloud cloud = plane_and_a_loner();
  for (std::size_t i = 0; i < cloud.size(); i += 7) cloud.points[i].z() = 0.25f;  // some relief
  const FpfhResult before = compute_fpfh(cloud, {0.4, 1});
  SampleCloud moved = cloud;
  for (std::size_t i = 0; i < moved.size(); ++i) {
    const Eigen::Vector3f p = cloud.points[i], n = cloud.normals[i];
    moved.points[i] = Eigen::Vector3f(-p.y() + 3.0f, p.x() - 2.0f, p.z() + 1.0f);
    moved.normals[i] = Eigen::Vector3f(-n.y(), n.x(), n.z());
  }
  const FpfhResult after = compute_fpfh(moved, {0.4, 2});
  EXPECT_EQ(after.described, before.described);
  EXPECT_EQ(after.features, before.features);
}

TEST(Fpfh, ADomeAndAPlaneDiffer) {
  const FpfhResult plane = compute_fpfh(plane_and_a_loner(), {0.3, 1});
  const FpfhResult curved = compute_fpfh(dome(), {0.6, 1});
  ASSERT_EQ(curved.described[3], 1);
  double distance = 0.0;
  for (int b = 0; b < 33; ++b) {
    distance += std::abs(curved.features[3][b] - plane.features[0][b]);
  }
  EXPECT_GT(distance, 50.0);  // of at most 600
  float sum = 0.0f;
  for (int b = 0; b < 11; ++b) sum += curved.features[3][b];
  EXPECT_NEAR(sum, 100.0f, 1e-3f);
}

}  // namespace
}  // namespace scanbench::registration

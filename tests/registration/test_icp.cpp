// Point-to-plane ICP recovers the true relative pose of two simulated campus
// scans from seeded pose errors of up to 3° and 0.5 m.
#include <gtest/gtest.h>

#include <cstdint>
#include <numbers>

#include "acquisition/simulation/pose_error.hpp"
#include "registration/association.hpp"
#include "registration/icp.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/simulated_campus.hpp"

namespace scanbench::registration {
namespace {

using test::campus;
using test::pose_error;
using test::PoseError;

// At 0.4° steps (900 × 225) with the virtual scanner's range noise ICP lands
// within 0.001° and 0.3 mm of the truth from every start below; the bounds
// leave a factor of ten for other toolchains and sanitizer builds.
constexpr double kMaxRotationErrorDeg = 0.01;
constexpr double kMaxTranslationErrorM = 0.003;

class IcpOnCampus : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const test::SimulatedCampus& c = campus(2);
    source_ = new SampleCloud(sample_scan(c.prepared[1], SampleSettings{}));
    target_ = new SampleCloud(sample_scan(c.prepared[0], SampleSettings{}));
  }
  static void TearDownTestSuite() {
    delete source_;
    delete target_;
    source_ = nullptr;
    target_ = nullptr;
  }
  static SampleCloud* source_;
  static SampleCloud* target_;
};

SampleCloud* IcpOnCampus::source_ = nullptr;
SampleCloud* IcpOnCampus::target_ = nullptr;

// The samples are usable points of their scan; at the true pose the two
// scans lie on each other, and ICP started there stays there.
TEST_F(IcpOnCampus, SamplesAreAlignedAtTheTruePoseWhichIcpKeeps) {
  const PreparedScan& scan = campus(2).prepared[1];
  ASSERT_GT(source_->size(), 1000u);
  ASSERT_EQ(source_->normals.size(), source_->size());
  ASSERT_EQ(source_->pixels.size(), source_->size());
  for (std::size_t s = 0; s < source_->size(); ++s) {
    const auto pixel = static_cast<std::size_t>(source_->pixels[s]);
    ASSERT_TRUE(scan.usable[pixel]) << s;
    ASSERT_EQ(source_->points[s], scan.points[pixel]) << s;
    ASSERT_NEAR(source_->normals[s].norm(), 1.0f, 1e-4f) << s;
  }

  const Eigen::Isometry3d truth = campus(2).true_relative(0, 1);
  const AlignmentQuality quality =
      measure_alignment(*source_, campus(2).prepared[0], truth, IcpSettings{});
  EXPECT_GT(quality.overlap, 0.2);  // 0.27 of scan 1's samples lie on scan 0's surfaces
  EXPECT_LT(quality.rms_m, 0.02);   // a few times the 5 mm range noise

  const IcpResult result =
      point_to_plane_icp(*source_, campus(2).prepared[0], truth, IcpSettings{}, target_);
  EXPECT_TRUE(result.converged);
  const PoseError error = pose_error(truth, result.T_target_source);
  EXPECT_LT(error.rotation_deg, kMaxRotationErrorDeg);
  EXPECT_LT(error.translation_m, kMaxTranslationErrorM);
}

// At the true pose almost no sample sits in space the target scanner saw
// through; turned about the scanner's vertical axis, the scan puts its
// buildings across the target's open ground.
TEST_F(IcpOnCampus, FreeSpaceViolationsSeparateTheTruePoseFromATurnedOne) {
  const Eigen::Isometry3d truth = campus(2).true_relative(0, 1);
  const PreparedScan& target = campus(2).prepared[0];
  EXPECT_LT(free_space_violation(*source_, target, truth, 0.05, 0), 0.01);
  for (const double turn_deg : {20.0, 90.0, 180.0}) {
    const Eigen::Isometry3d turned =
        truth * Eigen::AngleAxisd(turn_deg * std::numbers::pi / 180.0, Eigen::Vector3d::UnitZ());
    EXPECT_GT(free_space_violation(*source_, target, turned, 0.05, 0), 0.05) << turn_deg;
  }
}

TEST_F(IcpOnCampus, RecoversTheTruePoseFromSeededErrors) {
  const Eigen::Isometry3d truth = campus(2).true_relative(0, 1);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    acquisition::sim::Random random(acquisition::sim::hash_combine(0x1C9, seed));
    const Eigen::Isometry3d initial = truth * acquisition::sim::random_pose_error(3.0, 0.5, random);
    const PoseError start = pose_error(truth, initial);
    const IcpResult result =
        point_to_plane_icp(*source_, campus(2).prepared[0], initial, IcpSettings{}, target_);
    const PoseError error = pose_error(truth, result.T_target_source);
    SCOPED_TRACE(::testing::Message()
                 << "seed " << seed << ": start " << start.rotation_deg << "° "
                 << start.translation_m << " m, error " << error.rotation_deg << "° "
                 << error.translation_m << " m, " << result.iterations << " iterations");
    EXPECT_TRUE(result.converged);
    EXPECT_LT(error.rotation_deg, kMaxRotationErrorDeg);
    EXPECT_LT(error.translation_m, kMaxTranslationErrorM);
    EXPECT_GT(result.overlap, 0.2);
    EXPECT_LT(result.rms_m, 0.02);
    EXPECT_GE(result.correspondences, IcpSettings{}.min_correspondences);
  }
}

}  // namespace
}  // namespace scanbench::registration

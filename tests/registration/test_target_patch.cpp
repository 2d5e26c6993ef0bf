// Association through a patch of the target scan (registration/
// target_patch.hpp) gives the matches, the free-space share and the
// quality of association through the whole scan as long as the pose leaves
// every sample on a pixel of the patch, and says so, rather than answer,
// once a pose leaves it. EdgePatches visits an edge through its patch while
// the patch holds, through the target scan once it does not, and makes the
// patch anew there; where no temporary file takes the patches, it keeps
// none (they would grow with the campaign in memory).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>

#include "core/spill_file.hpp"
#include "registration/association.hpp"
#include "registration/edge_targets.hpp"
#include "registration/icp.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/simulated_campus.hpp"
#include "registration/target_patch.hpp"
#include "support/test_support.hpp"

namespace scanbench::registration {
namespace {

using test::campus;
using test::kDeg;

class PatchOnCampus : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    source_ = new SampleCloud(sample_scan(campus(2).prepared[1], SampleSettings{}));
  }
  static void TearDownTestSuite() {
    delete source_;
    source_ = nullptr;
  }
  static const PreparedScan& target() { return campus(2).prepared[0]; }
  static Eigen::Isometry3d truth() { return campus(2).true_relative(0, 1); }
  // The true pose turned by `deg` about the target's vertical axis.
  static Eigen::Isometry3d turned(double deg) {
    return Eigen::AngleAxisd(deg * kDeg, Eigen::Vector3d::UnitZ()) * truth();
  }
  static SampleCloud* source_;
};

SampleCloud* PatchOnCampus::source_ = nullptr;

// The association gate of the global refinement's last rounds.
constexpr AssociationGate kGate{0.05, 0.9};

TEST_F(PatchOnCampus, HoldsTheTargetAroundEverySamplesPixel) {
  const TargetPatch patch = patch_of(*source_, target(), truth(), 1);
  const PreparedScan& scan = target();
  ASSERT_GT(patch.size(), source_->size());
  ASSERT_TRUE(std::is_sorted(patch.pixels.begin(), patch.pixels.end()));
  for (std::size_t i = 0; i < patch.size(); ++i) {
    const auto k = static_cast<std::size_t>(patch.pixels[i]);
    ASSERT_EQ(patch.slot_of(patch.pixels[i]), static_cast<std::int64_t>(i));
    ASSERT_EQ(patch.range_m[i], scan.scan->range_m[k]) << i;
    ASSERT_EQ(patch.points[i], scan.points[k]) << i;
    ASSERT_EQ(patch.normals[i], scan.geometry->normal[k]) << i;
    ASSERT_EQ(patch.footprint_m[i], scan.geometry->footprint_m[k]) << i;
    ASSERT_EQ(patch.usable[i], scan.usable[k]) << i;
  }
  const Eigen::Isometry3f T = truth().cast<float>();
  const int columns = scan.scan->columns;
  for (const Eigen::Vector3f& sample : source_->points) {
    const std::int64_t pixel = scan.grid->pixel_of(Eigen::Vector3f(T * sample));
    if (pixel < 0) continue;
    const std::int64_t row = pixel / columns;
    const std::int64_t column = pixel % columns;
    for (const std::int64_t r : {row - 1, row, row + 1}) {
      if (r < 0 || r >= scan.scan->rows) continue;
      for (const std::int64_t c : {column - 1, column, column + 1}) {
        EXPECT_GE(patch.slot_of(r * columns + (c + columns) % columns), 0) << r << " " << c;
      }
    }
  }
  EXPECT_EQ(patch.slot_of(-5), -1);
}

// Made at the true pose, the patch answers as the whole scan there and at a
// pose turned by an eighth of a pixel (0.05° at 0.4° steps).
TEST_F(PatchOnCampus, AssociatesAsTheWholeScanWhileThePoseStaysWithinIt) {
  const TargetPatch patch = patch_of(*source_, target(), truth(), 1);
  const PatchedTarget patched{*target().grid, patch};
  for (const double deg : {0.0, 0.05, -0.05}) {
    SCOPED_TRACE(deg);
    const Eigen::Isometry3d T = turned(deg);
    const std::vector<Correspondence> whole = associate_samples(*source_, target(), T, kGate, 0);
    const std::optional<std::vector<Correspondence>> through =
        associate_samples(*source_, patched, T, kGate, 0);
    ASSERT_TRUE(through.has_value());
    ASSERT_GT(whole.size(), source_->size() / 5);
    ASSERT_EQ(through->size(), whole.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
      ASSERT_EQ((*through)[i].sample, whole[i].sample);
      ASSERT_EQ(patch.pixels[static_cast<std::size_t>((*through)[i].pixel)], whole[i].pixel);
    }
    const std::vector<PlaneCorrespondence> planes_whole =
        plane_correspondences(*source_, target(), whole);
    const std::vector<PlaneCorrespondence> planes_through =
        plane_correspondences(*source_, patched, *through);
    for (std::size_t i = 0; i < whole.size(); ++i) {
      ASSERT_EQ(planes_through[i].point, planes_whole[i].point);
      ASSERT_EQ(planes_through[i].normal, planes_whole[i].normal);
    }
    IcpSettings settings;
    const AlignmentQuality expected = measure_alignment(*source_, target(), T, settings);
    const std::optional<AlignmentQuality> quality =
        measure_alignment(*source_, patched, T, settings);
    ASSERT_TRUE(quality.has_value());
    EXPECT_EQ(quality->correspondences, expected.correspondences);
    EXPECT_EQ(quality->rms_m, expected.rms_m);
    EXPECT_EQ(quality->free_space_violation, expected.free_space_violation);
    EXPECT_GT(expected.correspondences, 0U);
  }
}

// Turned by five pixels (2°), the samples fall outside the patch: no answer.
TEST_F(PatchOnCampus, SaysSoWhenAPoseLeavesIt) {
  const TargetPatch patch = patch_of(*source_, target(), truth(), 1);
  const PatchedTarget patched{*target().grid, patch};
  const Eigen::Isometry3d T = turned(2.0);
  EXPECT_FALSE(associate_samples(*source_, patched, T, kGate, 0).has_value());
  EXPECT_FALSE(associate_with_free_space(*source_, patched, T, kGate, 0).has_value());
  EXPECT_FALSE(measure_alignment(*source_, patched, T, IcpSettings{}).has_value());
}

TEST_F(PatchOnCampus, EdgePatchesVisitThroughThePatchUntilAPoseLeavesIt) {
  ScansInMemory scans(campus(2).prepared);
  EdgePatches patches(2);
  const std::vector<ScanEdge> edges{{1, 0}};
  Eigen::Isometry3d T = truth();
  std::size_t scan_calls = 0;
  std::optional<std::size_t> matches;
  const auto visit = [&] {
    matches.reset();
    patches.visit(
        scans, edges,
        [&](const PatchedTarget& patched, std::size_t e) {
          EXPECT_EQ(e, 0U);
          const auto found = associate_samples(*source_, patched, T, kGate, 0);
          if (found) matches = found->size();
          return found.has_value();
        },
        [&](const PreparedScan& scan, std::size_t e) {
          EXPECT_EQ(&scan, &target());
          ++scan_calls;
          matches = associate_samples(*source_, scan, T, kGate, 0).size();
          patches.make(edges[e], *source_, scan, T);
        });
  };
  visit();  // no patch yet: the scan, which makes it
  EXPECT_EQ(scan_calls, 1U);
  const std::optional<std::size_t> at_truth = matches;
  visit();
  EXPECT_EQ(scan_calls, 1U);
  EXPECT_EQ(matches, at_truth);
  T = turned(2.0);
  visit();  // left the patch: the scan again, and a patch around the new pose
  EXPECT_EQ(scan_calls, 2U);
  visit();
  EXPECT_EQ(scan_calls, 2U);
  EXPECT_EQ(patches.patch_visits(), 2U);
  EXPECT_EQ(patches.scan_visits(), 2U);
  patches.drop(edges[0]);
  visit();
  EXPECT_EQ(scan_calls, 3U);
}

TEST_F(PatchOnCampus, WithoutATemporaryFileEdgesGoWithoutPatches) {
  const scanbench::test::NoTemporaryFiles no_files;
  if (core::SpillFile().usable()) GTEST_SKIP() << "a file could be made in /proc here";
  ScansInMemory scans(campus(2).prepared);
  EdgePatches patches(2);
  const std::vector<ScanEdge> edges{{1, 0}};
  patches.make(edges[0], *source_, target(), truth());
  std::size_t scan_calls = 0;
  patches.visit(
      scans, edges, [](const PatchedTarget&, std::size_t) { return true; },
      [&](const PreparedScan&, std::size_t) { ++scan_calls; });
  EXPECT_EQ(scan_calls, 1U);
  EXPECT_EQ(patches.patch_visits(), 0U);
}

}  // namespace
}  // namespace scanbench::registration

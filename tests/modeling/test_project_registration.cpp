// Schema version 3: registration reports, moved poses and merge keep masks.
#include <gtest/gtest.h>

#include "modeling/project.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;

TEST(ProjectRegistration, AVersionTwoProjectIsMigratedOnOpen) {
  const ScratchDir dir;
  const auto file = dir / "old.sbproj";
  { Project::create(file); }
  {
    test::RawDatabase raw(file);
    raw.execute("DROP TABLE registration_runs; DROP TABLE merge_masks; PRAGMA user_version = 2");
  }
  Project project = Project::open(file);
  EXPECT_EQ(project.schema_version(), kProjectSchemaVersion);
  EXPECT_FALSE(project.latest_registration_report().has_value());
}

TEST(ProjectRegistration, UpdatePoseMovesPoseScannerAndBounds) {
  const ScratchDir dir;
  Project project = Project::create(dir / "p.sbproj");
  acquisition::Scan scan = test::tiny_scan(true, false, false, 3, 4);
  auto transaction = project.begin();
  const std::int64_t id = project.insert_scan(scan);
  scan.T_world_scan.translation() += Eigen::Vector3d(10.0, -2.0, 0.5);
  project.update_pose(id, scan);
  transaction.commit();
  const StoredScanSummary stored = Project::open(dir / "p.sbproj").scans().at(0);
  EXPECT_TRUE(stored.summary.T_world_scan.isApprox(scan.T_world_scan));
  EXPECT_EQ(stored.summary.scanner.position_world, scan.T_world_scan.translation());
  const std::optional<Eigen::AlignedBox3d> bounds = acquisition::world_bounds(scan);
  ASSERT_TRUE(bounds && stored.summary.bbox_world);
  EXPECT_TRUE(stored.summary.bbox_world->isApprox(*bounds));
}

TEST(ProjectRegistration, KeepMasksRoundTripAndAreClearedTogether) {
  const ScratchDir dir;
  Project project = Project::create(dir / "p.sbproj");
  const acquisition::Scan scan = test::tiny_scan(true, false, false, 3, 4);
  auto transaction = project.begin();
  const std::int64_t a = project.insert_scan(scan);
  const std::int64_t b = project.insert_scan(scan);
  const std::vector<std::uint8_t> keep = {1, 0, 1, 1, 0, 0, 1, 0, 1, 1, 1, 0};
  project.store_keep_mask(a, keep, "{}");
  project.store_keep_mask(b, keep, "{}");
  project.store_registration("{}", R"({"overall": {"converged": true}})");
  transaction.commit();
  EXPECT_EQ(project.load_keep_mask(a), keep);
  EXPECT_EQ(project.latest_registration_report(), R"({"overall": {"converged": true}})");
  auto clearing = project.begin();
  project.clear_keep_masks();
  clearing.commit();
  EXPECT_FALSE(project.load_keep_mask(a).has_value());
  EXPECT_FALSE(project.load_keep_mask(b).has_value());
}

}  // namespace
}  // namespace scanbench::modeling

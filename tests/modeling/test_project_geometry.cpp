// Schema version 2: per-point geometry stored beside the scans.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "modeling/geometry_stage.hpp"
#include "modeling/import_scans.hpp"
#include "modeling/project.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;

acquisition::GeometryResult made_up_geometry(std::size_t n) {
  acquisition::GeometryResult result;
  for (std::size_t i = 0; i < n; ++i) {
    result.geometry.footprint_m.push_back(0.01f * static_cast<float>(i));
    result.geometry.normal.emplace_back(0.0f, -1.0f, static_cast<float>(i) * 0.0f);
    result.geometry.confidence.push_back(i % 2 ? 0.5f : 0.0f);
    result.geometry.flags.push_back(static_cast<std::uint8_t>(i % 4));
  }
  result.normals = n / 2;
  return result;
}

TEST(ProjectGeometry, StoresAndLoadsBitIdenticalGeometry) {
  const ScratchDir dir;
  Project project = Project::create(dir / "p.sbproj");
  const acquisition::Scan scan = test::tiny_scan(true, true, true, 3, 4);
  auto transaction = project.begin();
  const std::int64_t id = project.insert_scan(scan);
  EXPECT_FALSE(project.load_geometry(id).has_value());
  const acquisition::GeometryResult geometry = made_up_geometry(scan.pixel_count());
  project.store_geometry(id, geometry, "{}");
  transaction.commit();
  const std::optional<acquisition::ScanGeometry> back =
      Project::open(dir / "p.sbproj").load_geometry(id);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->footprint_m, geometry.geometry.footprint_m);
  EXPECT_EQ(back->normal, geometry.geometry.normal);
  EXPECT_EQ(back->confidence, geometry.geometry.confidence);
  EXPECT_EQ(back->flags, geometry.geometry.flags);
}

TEST(ProjectGeometry, AVersionOneProjectIsMigratedOnOpen) {
  const ScratchDir dir;
  const auto file = dir / "old.sbproj";
  { Project::create(file); }
  {
    test::RawDatabase raw(file);
    raw.execute(
        "DROP TABLE scan_geometry; DROP TABLE registration_runs; DROP TABLE merge_masks; "
        "PRAGMA user_version = 1");
  }
  Project project = Project::open(file);
  EXPECT_EQ(project.schema_version(), kProjectSchemaVersion);
  auto transaction = project.begin();
  const std::int64_t id = project.insert_scan(test::tiny_scan(true, false, false));
  project.store_geometry(id, made_up_geometry(6), "{}");
  transaction.commit();
  EXPECT_TRUE(project.load_geometry(id).has_value());
}

TEST(GeometryStage, ComputesAndStoresEveryScanInOneTransaction) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  import_scan_files(file,
                    std::vector<std::filesystem::path>{test::fixture("good/ptx/two_scans.ptx")});
  GeometryStageSettings settings;
  settings.geometry.window_radius = 2;
  settings.geometry.edge_window_radius = 1;
  std::size_t reported = 0;
  settings.on_scan_done = [&](std::size_t done, std::size_t total, const std::string&) {
    reported = done;
    EXPECT_EQ(total, 2u);
  };
  const GeometryStageResult result = compute_project_geometry(file, settings);
  ASSERT_EQ(result.scans.size(), 2u);
  EXPECT_EQ(reported, 2u);
  const Project project = Project::open(file);
  for (const auto& stored : project.scans()) {
    const auto geometry = project.load_geometry(stored.id);
    ASSERT_TRUE(geometry.has_value());
    EXPECT_EQ(geometry->normal.size(),
              static_cast<std::size_t>(stored.summary.rows * stored.summary.columns));
  }
}

TEST(GeometryStage, AForeignFileIsRefused) {
  const ScratchDir dir;
  EXPECT_THROW(compute_project_geometry(test::fixture("bad/project_not_sqlite.sbproj")),
               core::InputError);
}

}  // namespace
}  // namespace scanbench::modeling

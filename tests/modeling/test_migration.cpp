// Real project files written by earlier scanbench versions
// (fixtures/projects/versionN.sbproj, made by the builds that introduced
// each schema version) open, migrate in one step, and keep their data.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;

// A migrated copy of fixtures/projects/version<version>.sbproj.
std::filesystem::path migrated_copy(const ScratchDir& dir, int version) {
  const auto file = dir / ("version" + std::to_string(version) + ".sbproj");
  std::filesystem::copy_file(
      test::fixture("projects/version" + std::to_string(version) + ".sbproj"), file);
  return file;
}

std::vector<std::string> names(const store::Project& project) {
  std::vector<std::string> out;
  for (const store::StoredScanSummary& s : project.scans()) out.push_back(s.summary.name);
  return out;
}

std::size_t count_ones(const std::vector<std::uint8_t>& mask) {
  return static_cast<std::size_t>(std::count(mask.begin(), mask.end(), std::uint8_t{1}));
}

// fixtures/projects/version10.sbproj: version9.sbproj (below) opened by the
// build that introduced version 10, then `scanbench geometry` run on it: the
// grids' geometry layers written by rows, their frames in the column
// `frame`; the scattered scan's written whole, in `data`.
TEST(CurrentVersion, AFileOfTheCurrentVersionOpensUnchangedWithLayersWrittenByRows) {
  static_assert(store::kProjectSchemaVersion == 10, "add fixtures/projects/version11.sbproj");
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 10);
  const std::string before = test::read_file_bytes(file);
  {
    const store::Project project = store::Project::open(file);
    const std::vector<store::StoredScanSummary> scans = project.scans();
    ASSERT_EQ(scans.size(), 6u);
    const std::optional<acquisition::ScanGeometry> grid =
        store::load_geometry(project, scans[3].id);
    ASSERT_TRUE(grid.has_value());
    EXPECT_EQ(std::count_if(grid->confidence.begin(), grid->confidence.end(),
                            [](float c) { return c > 0.0f; }),
              33);
    EXPECT_EQ(store::load_geometry(project, scans[5].id)->normal.size(), 63u * 64u);
    auto normals =
        project.open_layer_rows(scans[3].id, store::layer::kNormal, store::ElementType::kF32x3);
    ASSERT_TRUE(normals.has_value());
    std::vector<Eigen::Vector3f> by_rows(grid->normal.size());
    normals->read(std::span(by_rows));
    EXPECT_EQ(by_rows, grid->normal);
    const store::Project::CheckReport report = project.check();
    EXPECT_TRUE(report.damage.empty());
    EXPECT_EQ(report.layers, 45u);
  }
  EXPECT_EQ(test::read_file_bytes(file), before);
}

// fixtures/projects/version9.sbproj: version8.sbproj (below) opened by the
// build that introduced version 9, then fixtures/good/e57/unstructured_sphere.e57
// imported: an unstructured cloud of 4 000 points kept as a scattered scan.
TEST(Migration, VersionNineKeepsItsScatteredScanAndItsLayersReadByRows) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 9);
  const store::Project project = store::Project::open(file);
  EXPECT_EQ(project.schema_version(), store::kProjectSchemaVersion);
  const std::vector<store::StoredScanSummary> scans = project.scans();
  ASSERT_EQ(scans.size(), 6u);
  EXPECT_FALSE(scans[4].summary.scattered);
  EXPECT_TRUE(scans[5].summary.scattered);
  EXPECT_EQ(scans[5].summary.valid_points, 4000u);
  const acquisition::Scan sphere = project.load_scan(scans[5].id);
  EXPECT_TRUE(sphere.is_scattered());
  EXPECT_EQ(acquisition::check_consistency(sphere), "");
  // A layer stored whole before version 10 reads by rows.
  auto range = project.open_layer_rows(scans[5].id, store::layer::kRange, store::ElementType::kF32);
  ASSERT_TRUE(range.has_value());
  std::vector<float> by_rows(sphere.pixel_count());
  range->read(std::span(by_rows));
  EXPECT_EQ(by_rows, sphere.range_m);
  EXPECT_TRUE(project.check().damage.empty());
}

// fixtures/projects/version8.sbproj: version7.sbproj (below) opened by the
// build that introduced version 8, then fixtures/good/ptx/georef_world_1e5.ptx
// imported as station.ptx (its source file recorded), the groups "site" and
// "annex" made by one script, and the second undone.
TEST(Migration, VersionEightKeepsItsJournalIndexedAndItsScansAreGrids) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 8);
  {
    const store::Project project = store::Project::open(file);
    const std::map<std::int64_t, acquisition::ScanSource> sources = project.scan_sources();
    ASSERT_EQ(sources.size(), 2u);
    ASSERT_EQ(sources.at(5).files.size(), 1u);
    EXPECT_EQ(std::filesystem::path(sources.at(5).files[0].path).filename(), "station.ptx");
    EXPECT_NE(sources.at(5).files[0].inode, 0u);
    const std::vector<store::CommandRecord> history = project.history();
    EXPECT_EQ(history.back().name, "group");
    EXPECT_EQ(history.back().state, store::CommandState::kUndone);
    ASSERT_EQ(project.object_nodes().size(), 3u);
  }
  for (const store::StoredScanSummary& s : store::Project::open(file).scans()) {
    EXPECT_FALSE(s.summary.scattered) << s.summary.name;
  }
  test::RawDatabase raw(file);
  for (const char* index : {"commands_undone", "commands_pending"}) {
    EXPECT_EQ(raw.text(std::string("SELECT name FROM sqlite_schema WHERE name = '") + index + "'"),
              index);
  }
  store::Project project = store::Project::open(file);
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_EQ(project.object_nodes().size(), 4u);
  EXPECT_TRUE(project.check().damage.empty());
}

// fixtures/projects/version7.sbproj: version6.sbproj (below) opened by the
// build that introduced version 7, then
// fixtures/good/e57/structured_spherical.e57 imported: a scan with its
// source (one record not placed) and two images, one tied to no scan.
TEST(Migration, VersionSevenKeepsItsSourcesAndImages) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 7);
  {
    store::Project project = store::Project::open(file);
    EXPECT_EQ(names(project),
              (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color", "structured"}));
    const auto sources = project.scan_sources();
    ASSERT_EQ(sources.size(), 1u) << "scans imported before version 7 have none";
    EXPECT_EQ(sources.at(4).guid, "{scan-structured}");
    EXPECT_EQ(sources.at(4).unplaced_points, 1u);
    const std::vector<store::StoredImage> images = project.images(true);
    ASSERT_EQ(images.size(), 2u);
    EXPECT_EQ(images[0].scan_id, 4);
    EXPECT_EQ(images[0].image.format, "png");
    EXPECT_FALSE(images[1].scan_id.has_value());
    EXPECT_EQ(images[1].image.data.size(), 662u);
    EXPECT_EQ(project.history().back().name, "import");
  }
  store::Project project = store::Project::open(file);
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_TRUE(project.images(false).empty()) << "the images go with their import";
  EXPECT_TRUE(project.scan_sources().empty());
  EXPECT_TRUE(project.check().damage.empty());
}

// fixtures/projects/version6.sbproj: version5.sbproj (below) opened by the
// build that introduced version 6 (the undone rename is discarded by the
// next command), then "wall south" recoloured (brightness 12, saturation
// 0.8) and a hue edit of "north hall" undone.
TEST(Migration, VersionSixKeepsItsColourEditsAndTakesImages) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 6);
  {
    store::Project project = store::Project::open(file);
    EXPECT_EQ(names(project), (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color"}));
    const std::vector<store::CommandRecord> history = project.history();
    ASSERT_EQ(history.size(), 4u);
    EXPECT_EQ(history[2].name, "recolor");
    EXPECT_EQ(history[3].name, "recolor");
    EXPECT_EQ(history[3].state, store::CommandState::kUndone);
    const std::vector<store::ObjectNode> nodes = project.object_nodes();
    ASSERT_EQ(nodes.size(), 2u);
    EXPECT_TRUE(nodes[0].color.empty());
    EXPECT_EQ(nodes[1].color.brightness, 12.0);
    EXPECT_EQ(nodes[1].color.saturation, 0.8);
    EXPECT_FALSE(nodes[1].color.hue_deg.has_value());
    EXPECT_TRUE(project.scan_color_corrections().empty());
    EXPECT_TRUE(project.scan_sources().empty());
    EXPECT_TRUE(project.images(false).empty());
  }
  store::Project project = store::Project::open(file);
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_EQ(project.object_nodes()[0].color.hue_deg, 20.0);
  acquisition::ScanImage image;
  image.format = "png";
  image.data = {1, 2, 3};
  store::Project::Edit edit = project.begin_command("import", "{}");
  project.insert_image(edit, 1, project.scans().front().summary.T_world_scan, image);
  edit.commit("{}");
  EXPECT_EQ(project.images(true).at(0).image.data, image.data);
  EXPECT_TRUE(project.check().damage.empty());
}

// fixtures/projects/version5.sbproj: version4.sbproj (below) opened by the
// build that introduced version 5, then the nodes "north hall" (a group) and
// "wall south" (an object in it) created, and a rename of the wall undone.
// Its nodes keep their checksums and have no colour edits.
TEST(Migration, VersionFiveKeepsItsTreeAndTakesColourEdits) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 5);
  store::Project project = store::Project::open(file);
  EXPECT_EQ(project.schema_version(), store::kProjectSchemaVersion);
  const std::vector<store::CommandRecord> history = project.history();
  ASSERT_EQ(history.size(), 3u);
  EXPECT_EQ(history[2].state, store::CommandState::kUndone);
  std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].name, "wall south");
  EXPECT_EQ(nodes[1].points, 5);
  EXPECT_TRUE(nodes[1].color.empty());
  EXPECT_TRUE(project.check().damage.empty());
  ASSERT_TRUE(project.redo().has_value());
  nodes = project.object_nodes();
  EXPECT_EQ(nodes[1].name, "wall west");
  nodes[1].color.hue_deg = 45.0;
  store::Project::Edit edit = project.begin_command("recolor", "{}");
  project.put_node(edit, nodes[1]);
  edit.commit("{}");
  EXPECT_EQ(project.object_nodes()[1].color.hue_deg, 45.0);
  EXPECT_TRUE(project.check().damage.empty());
}

// fixtures/projects/version4.sbproj: two_scans.ptx and tiny_color.ptx
// imported, then geometry computed and undone.
TEST(Migration, VersionFourKeepsItsJournalWithTheUndoneGeometry) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, 4);
  store::Project project = store::Project::open(file);
  EXPECT_EQ(names(project), (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color"}));
  const std::vector<store::CommandRecord> history = project.history();
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[1].name, "geometry");
  EXPECT_EQ(history[1].state, store::CommandState::kUndone);
  EXPECT_TRUE(project.object_nodes().empty());
  EXPECT_FALSE(store::load_geometry(project, 3).has_value());
  ASSERT_TRUE(project.redo().has_value());
  const std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project, 3);
  ASSERT_TRUE(geometry.has_value());
  EXPECT_EQ(geometry->footprint_m.size(), 6u);  // tiny_color is 2 × 3
}

class Migration : public ::testing::TestWithParam<int> {};

TEST_P(Migration, OpensAtTheCurrentVersionWithEveryScanLoadable) {
  const ScratchDir dir;
  const auto file = migrated_copy(dir, GetParam());
  {
    const store::Project project = store::Project::open(file);
    EXPECT_EQ(project.schema_version(), store::kProjectSchemaVersion);
    for (const store::StoredScanSummary& stored : project.scans()) {
      const acquisition::Scan scan = project.load_scan(stored.id);
      EXPECT_EQ(acquisition::count_valid(scan), stored.summary.valid_points) << stored.id;
    }
  }
  test::RawDatabase raw(file);
  EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
  EXPECT_EQ(raw.text("PRAGMA foreign_key_check"), "");
  for (const char* gone :
       {"scan_channels", "scan_geometry", "merge_masks", "registration_runs", "scans_v3"}) {
    EXPECT_EQ(raw.text(std::string("SELECT name FROM sqlite_schema WHERE name = '") + gone + "'"),
              "")
        << gone;
  }
}

INSTANTIATE_TEST_SUITE_P(Versions, Migration, ::testing::Values(1, 2, 3, 4, 5, 6, 7));

TEST(Migration, VersionOneKeepsItsScans) {
  const ScratchDir dir;
  const store::Project project = store::Project::open(migrated_copy(dir, 1));
  EXPECT_EQ(names(project), (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color",
                                                      "lobby", "organized_ascii"}));
  const acquisition::Scan color = project.load_scan(3);
  EXPECT_TRUE(color.has_color());
  EXPECT_FALSE(store::load_geometry(project, 1).has_value());
  EXPECT_FALSE(project.load_scan(5).is_spherical());  // the PCD's per-pixel directions
}

TEST(Migration, VersionTwoKeepsItsGeometry) {
  const ScratchDir dir;
  const store::Project project = store::Project::open(migrated_copy(dir, 2));
  ASSERT_EQ(project.scans().size(), 5u);
  for (const store::StoredScanSummary& stored : project.scans()) {
    const std::optional<acquisition::ScanGeometry> geometry =
        store::load_geometry(project, stored.id);
    ASSERT_TRUE(geometry.has_value()) << stored.id;
    EXPECT_EQ(geometry->normal.size(), project.load_scan(stored.id).pixel_count());
  }
  // two_scans had 2 normals (scanbench geometry --window 2 --edge-window 1 on v2).
  const auto geometry = store::load_geometry(project, 1);
  EXPECT_EQ(std::count_if(geometry->confidence.begin(), geometry->confidence.end(),
                          [](float c) { return c > 0.0f; }),
            2);
}

TEST(Migration, VersionThreeKeepsPosesKeepMasksAndTheRegistrationReport) {
  const ScratchDir dir;
  const store::Project project = store::Project::open(migrated_copy(dir, 3));
  EXPECT_EQ(names(project), (std::vector<std::string>{"campus_scan_01", "campus_scan_02"}));
  // As `scanbench merge` reported when the fixture was made.
  EXPECT_EQ(count_ones(*store::load_keep_mask(project, 1)), 6803u);
  EXPECT_EQ(count_ones(*store::load_keep_mask(project, 2)), 6415u);
  // What the project held, as the journal entries that made it, in order.
  const std::vector<store::CommandRecord> history = project.history();
  ASSERT_EQ(history.size(), 4u);
  EXPECT_EQ(history[0].name, "migrate");
  EXPECT_THAT(history[0].settings, ::testing::HasSubstr("\"from_schema_version\":3"));
  EXPECT_EQ(history[1].name, "geometry");
  EXPECT_THAT(history[1].settings, ::testing::HasSubstr("\"window_radius\":16"));
  EXPECT_THAT(history[1].result, ::testing::HasSubstr("\"mixed_pixels\""));
  EXPECT_EQ(history[2].name, "register");
  EXPECT_THAT(history[2].result, ::testing::HasSubstr("\"converged\":true"));
  EXPECT_EQ(history[3].name, "merge");
  EXPECT_THAT(history[3].result, ::testing::HasSubstr("\"kept\":13218"));
  for (const store::CommandRecord& c : history) EXPECT_FALSE(c.undoable) << c.name;
  EXPECT_LE(history[0].created_at, history[1].created_at);
  EXPECT_EQ(project.latest_result("register"), history[2].result);
  // The registered pose of the second scan (as the report has it), not the
  // perturbed one of its file.
  const nlohmann::json report = nlohmann::json::parse(history[2].result);
  const nlohmann::json& pose = report["poses"][1];
  const Eigen::Isometry3d stored = project.scans()[1].summary.T_world_scan;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      EXPECT_EQ(stored(row, col), pose["T_world_scan"][row][col].get<double>());
      EXPECT_NE(stored(row, col), pose["initial_T_world_scan"][row][col].get<double>());
    }
  }
}

}  // namespace
}  // namespace scanbench::modeling

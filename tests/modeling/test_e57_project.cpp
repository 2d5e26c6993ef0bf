// E57 through the project: E57 → project → E57 → project and
// PTX → project → E57 → project give the same grids, validity, intensity
// and colour, positions within 0.1 mm, and (E57) the same images and
// guids; a bad E57 file changes nothing.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "modeling/color_commands.hpp"
#include "modeling/export_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/selection_commands.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::fixture;
using test::import_files;
using test::ScratchDir;

std::filesystem::path export_e57(const std::filesystem::path& project,
                                 const std::filesystem::path& output) {
  ExportSettings settings;
  settings.format = ExportFormat::kE57;
  settings.output = output;
  export_project(store::Project::open_for_reading(project), settings);
  return output;
}

void expect_same_scans(const std::filesystem::path& first, const std::filesystem::path& second) {
  const store::Project a = store::Project::open_for_reading(first);
  const store::Project b = store::Project::open_for_reading(second);
  const auto scans_a = a.scans();
  const auto scans_b = b.scans();
  ASSERT_EQ(scans_a.size(), scans_b.size());
  for (std::size_t k = 0; k < scans_a.size(); ++k) {
    const acquisition::Scan x = a.load_scan(scans_a[k].id);
    const acquisition::Scan y = b.load_scan(scans_b[k].id);
    EXPECT_EQ(x.name, y.name);
    ASSERT_EQ(x.rows, y.rows);
    ASSERT_EQ(x.columns, y.columns);
    EXPECT_EQ(x.valid, y.valid) << x.name;
    EXPECT_EQ(x.intensity, y.intensity) << x.name;
    EXPECT_EQ(x.rgb, y.rgb) << x.name;
    double worst = 0.0;
    for (int r = 0; r < x.rows; ++r) {
      for (int c = 0; c < x.columns; ++c) {
        if (!x.valid[x.index(r, c)]) continue;
        worst = std::max(
            worst,
            (acquisition::point_in_world(x, r, c) - acquisition::point_in_world(y, r, c)).norm());
      }
    }
    EXPECT_LT(worst, 1e-4) << x.name << ": every point within 0.1 mm";
  }
}

TEST(E57Project, RoundTripKeepsScansImagesAndGuids) {
  const ScratchDir dir;
  import_files(dir / "a.sbproj", {fixture("good/e57/structured_spherical.e57")});
  const auto file = export_e57(dir / "a.sbproj", dir / "a.e57");
  const ImportResult again = import_files(dir / "b.sbproj", {file});
  EXPECT_EQ(again.images, 2u);
  expect_same_scans(dir / "a.sbproj", dir / "b.sbproj");
  const store::Project b = store::Project::open_for_reading(dir / "b.sbproj");
  EXPECT_EQ(b.scan_sources().at(1).guid, "{scan-structured}");
  EXPECT_EQ(b.scan_sources().at(1).unplaced_points, 0u) << "the exported grid holds first returns";
  const std::vector<store::StoredImage> images = b.images(true);
  const std::vector<store::StoredImage> original =
      store::Project::open_for_reading(dir / "a.sbproj").images(true);
  ASSERT_EQ(images.size(), original.size());
  for (std::size_t i = 0; i < images.size(); ++i) {
    EXPECT_EQ(images[i].scan_id, original[i].scan_id);
    EXPECT_EQ(images[i].image.data, original[i].image.data);
    EXPECT_EQ(images[i].image.guid, original[i].image.guid);
    EXPECT_EQ(images[i].image.projection, original[i].image.projection);
    EXPECT_EQ(images[i].image.T_world_image.matrix(), original[i].image.T_world_image.matrix());
  }
  // And once more: the second export reads back to the same project.
  import_files(dir / "c.sbproj", {export_e57(dir / "b.sbproj", dir / "b.e57")});
  expect_same_scans(dir / "b.sbproj", dir / "c.sbproj");
}

TEST(E57Project, ImagesFollowTheirScanWhenItMoves) {
  const ScratchDir dir;
  import_files(dir / "p.sbproj", {fixture("good/e57/structured_spherical.e57")});
  store::Project project = store::Project::open(dir / "p.sbproj");
  const store::StoredImage before = project.images(false).at(0);
  ASSERT_EQ(before.scan_id, 1);
  const Eigen::Isometry3d was = project.scans().at(0).summary.T_world_scan;
  acquisition::Scan scan = project.load_scan(1);
  scan.T_world_scan = Eigen::Translation3d(5.0, -2.0, 0.5) *
                      Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) * scan.T_world_scan;
  store::Project::Edit edit = project.begin_command("register", "{}");
  project.set_pose(edit, 1, scan);
  edit.commit("{}");
  const store::StoredImage after = project.images(false).at(0);
  const Eigen::Isometry3d expected = scan.T_world_scan * was.inverse() * before.image.T_world_image;
  EXPECT_TRUE(after.image.T_world_image.isApprox(expected, 1e-12));
  EXPECT_FALSE(after.image.T_world_image.isApprox(before.image.T_world_image, 1e-6));
  // The loose image stays where it was.
  EXPECT_TRUE(
      project.images(false).at(1).image.T_world_image.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(E57Project, PtxThroughE57KeepsEveryGeoreferencedScan) {
  const ScratchDir dir;
  import_files(dir / "ptx.sbproj",
               {fixture("good/ptx/two_scans.ptx"), fixture("good/ptx/tiny_color.ptx"),
                fixture("good/ptx/georef_world_1e7.ptx"), fixture("good/ptx/irregular.ptx")});
  import_files(dir / "e57.sbproj", {export_e57(dir / "ptx.sbproj", dir / "ptx.e57")});
  expect_same_scans(dir / "ptx.sbproj", dir / "e57.sbproj");
}

TEST(E57Project, TheCoordinateSystemGoesBackOutAndIsNeverMixed) {
  const ScratchDir dir;
  import_files(dir / "geo.sbproj", {fixture("good/e57/georeferenced.e57")});
  import_files(dir / "again.sbproj", {export_e57(dir / "geo.sbproj", dir / "geo.e57")});
  const auto sources = store::Project::open_for_reading(dir / "again.sbproj").scan_sources();
  ASSERT_EQ(sources.size(), 2u);
  EXPECT_EQ(sources.at(1).coordinate_metadata, "EPSG:25832");
  // LAS names a coordinate system in WKT only: a code is not written, and
  // the export says so.
  ExportSettings las;
  las.format = ExportFormat::kLas;
  las.output = dir / "geo.las";
  las.scan_id = 1;
  const ExportResult written = export_project(store::Project::open_for_reading(dir / "geo.sbproj"), las);
  ASSERT_EQ(written.notes.size(), 1u);
  EXPECT_THAT(written.notes.front(), ::testing::HasSubstr("\"EPSG:25832\" is not OGC WKT"));
  // A scan of a file that names no system joins any; one that names another
  // is refused.
  import_files(dir / "geo.sbproj", {fixture("good/e57/structured_spherical.e57")});
  EXPECT_NO_THROW(export_e57(dir / "geo.sbproj", dir / "mixed.e57"));
  {
    store::Project project = store::Project::open(dir / "geo.sbproj");
    store::Project::Edit edit = project.begin_command("import", "{}");
    acquisition::Scan scan = project.load_scan(1);
    const std::int64_t id = project.insert_scan(edit, store::encode_scan(scan));
    acquisition::ScanSource other;
    other.format = "e57";
    other.coordinate_metadata = "EPSG:4326";
    project.put_scan_source(edit, id, other);
    edit.commit("{}");
  }
  try {
    export_e57(dir / "geo.sbproj", dir / "two_systems.e57");
    FAIL() << "scans of two coordinate systems in one file";
  } catch (const core::InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("another coordinate system"));
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "two_systems.e57"));
}

TEST(E57Project, AnUnstructuredCloudComesBackWholeInItsOrder) {
  const ScratchDir dir;
  import_files(dir / "a.sbproj", {fixture("good/e57/unstructured_sphere.e57")});
  const auto file = export_e57(dir / "a.sbproj", dir / "a.e57");
  const ImportResult again = import_files(dir / "b.sbproj", {file});
  EXPECT_EQ(again.unplaced_points, 0u);
  expect_same_scans(dir / "a.sbproj", dir / "b.sbproj");
  const store::Project b = store::Project::open_for_reading(dir / "b.sbproj");
  EXPECT_TRUE(b.load_scan(1).is_scattered());
  EXPECT_EQ(b.scan_sources().at(1).points_in_file, 4000u) << "one record per point, no padding";
}

TEST(E57Project, GridOnlyToolsSayAnUnstructuredCloudHasNoGrid) {
  const ScratchDir dir;
  import_files(dir / "a.sbproj", {fixture("good/e57/unstructured_sphere.e57")});
  ExportSettings ptx;
  ptx.format = ExportFormat::kPtx;
  ptx.output = dir / "a.ptx";
  EXPECT_THAT([&] { export_project(store::Project::open_for_reading(dir / "a.sbproj"), ptx); },
              ::testing::ThrowsMessage<core::InputError>(
                  ::testing::HasSubstr("is an unstructured cloud, and a PTX holds scan grids")));
  EXPECT_FALSE(std::filesystem::exists(dir / "a.ptx"));
  segmentation::PixelSet selection;
  SelectSettings seed;
  seed.scan_id = 1;
  EXPECT_THAT([&] { select_region(store::Project::open(dir / "a.sbproj"), seed, selection); },
              ::testing::ThrowsMessage<core::InputError>(
                  ::testing::HasSubstr("is an unstructured cloud (imported without a scan grid)")));
  // An object picked in 3D is kept; a region of the range image is refused.
  store::Project project = store::Project::open(dir / "a.sbproj");
  segmentation::PixelSet picked;
  for (std::uint32_t i = 0; i < 100; ++i) picked.push_back(i);
  CommitSettings commit;
  commit.scan_id = 1;
  commit.name = "cap";
  const NodeCommandResult cap = commit_selection(project, commit, picked);
  CloneSettings region;
  region.target = cap.node_id;
  region.source_region = PixelRect{1, 0, 1, 0, 10};
  EXPECT_THAT([&] { clone_color(project, region); },
              ::testing::ThrowsMessage<core::InputError>(
                  ::testing::HasSubstr("a region of its range image is not a region")));
}

TEST(E57Project, ABadFileChangesNothing) {
  const ScratchDir dir;
  const auto project = dir / "p.sbproj";
  import_files(project, {fixture("good/ptx/tiny_color.ptx")});
  for (const char* bad : {"bad/e57_bad_checksum.e57", "bad/e57_truncated_section.e57"}) {
    // The good file first: its scan is written, then taken back.
    EXPECT_THROW(import_files(project, {fixture("good/e57/georeferenced.e57"), fixture(bad)}),
                 core::InputError)
        << bad;
  }
  const store::Project opened = store::Project::open_for_reading(project);
  EXPECT_EQ(opened.scans().size(), 1u);
  EXPECT_EQ(opened.history().size(), 1u) << "no trace of the refused imports";
  EXPECT_TRUE(opened.images(false).empty());
  EXPECT_TRUE(opened.check().damage.empty());
}

}  // namespace
}  // namespace scanbench::modeling

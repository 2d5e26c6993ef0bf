// Project: creation, scan round trips, summaries and edits. Refusals and
// crash safety are in test_project_files.cpp, the journal in test_journal.cpp.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <tuple>

#include "acquisition/scan_summary.hpp"
#include "core/errors.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using core::InputError;
using test::expect_identical;
using test::RawDatabase;
using test::ScratchDir;
using test::tiny_scan;
using ::testing::HasSubstr;

using test::insert_committed;

TEST(Project, CreateMakesAnEmptyProjectOfTheCurrentSchema) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  {
    const store::Project project = store::Project::create(file);
    EXPECT_EQ(project.path(), file);
    EXPECT_EQ(project.schema_version(), store::kProjectSchemaVersion);
    EXPECT_TRUE(project.scans().empty());
  }
  RawDatabase raw(file);
  EXPECT_EQ(raw.text("PRAGMA application_id"), std::to_string(store::kProjectApplicationId));
  EXPECT_EQ(raw.text("PRAGMA user_version"), std::to_string(store::kProjectSchemaVersion));
  EXPECT_EQ(raw.text("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw.text("SELECT value FROM meta WHERE key = 'created_by'"), "scanbench");
  EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
}

TEST(Project, OpenFindsWhatCreateLeft) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  { store::Project::create(file); }
  EXPECT_TRUE(test::no_side_files(file));  // the last close checkpoints the WAL away
  const store::Project project = store::Project::open(file);
  EXPECT_EQ(project.schema_version(), store::kProjectSchemaVersion);
  EXPECT_TRUE(project.scans().empty());
}

TEST(Project, OpenOrCreateCreatesOnceThenOpens) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  {
    store::Project project = store::Project::open_or_create(file);
    insert_committed(project, tiny_scan(true, false, false));
  }
  EXPECT_EQ(store::Project::open_or_create(file).scans().size(), 1u);
}

TEST(Project, CreateRefusesAnExistingFileAndLeavesItAlone) {
  const ScratchDir dir;
  const auto file = dir / "notes.sbproj";
  {
    store::Project project = store::Project::create(file);
    insert_committed(project, tiny_scan(true, true, true));
  }
  const std::string before = test::read_file_bytes(file);
  try {
    store::Project::create(file);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.file(), file.string());
    EXPECT_THAT(error.what(), HasSubstr("already exists"));
  }
  EXPECT_EQ(test::read_file_bytes(file), before);
  EXPECT_EQ(store::Project::open(file).scans().size(), 1u);
}

TEST(Project, CreateInAMissingFolderIsAnInputError) {
  const ScratchDir dir;
  EXPECT_THROW(store::Project::create(dir / "no such folder" / "site.sbproj"), core::InputError);
}

// (spherical, intensity, color)
class ProjectRoundTrip : public ::testing::TestWithParam<std::tuple<bool, bool, bool>> {};

TEST_P(ProjectRoundTrip, LoadReturnsTheInsertedScanBitForBit) {
  const auto [spherical, intensity, color] = GetParam();
  const acquisition::Scan scan = tiny_scan(spherical, intensity, color);
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  std::int64_t id = 0;
  {
    store::Project project = store::Project::create(file);
    id = insert_committed(project, scan);
    expect_identical(project.load_scan(id), scan);  // same connection
  }
  expect_identical(store::Project::open(file).load_scan(id), scan);  // after reopening
}

INSTANTIATE_TEST_SUITE_P(AngleModelsAndChannels, ProjectRoundTrip,
                         ::testing::Combine(::testing::Bool(), ::testing::Bool(),
                                            ::testing::Bool()));

TEST(Project, EmptyGridRoundTrips) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "site.sbproj");
  for (const bool spherical : {true, false}) {
    const acquisition::Scan scan = tiny_scan(spherical, false, false, 0, 0);
    expect_identical(project.load_scan(insert_committed(project, scan)), scan);
  }
}

TEST(Project, ScansListsSummariesInIdOrder) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "site.sbproj");
  acquisition::Scan first = tiny_scan(true, true, false);
  acquisition::Scan empty = tiny_scan(false, false, true);
  empty.name = "no returns";
  std::fill(empty.valid.begin(), empty.valid.end(), 0);
  const std::int64_t first_id = insert_committed(project, first);
  const std::int64_t empty_id = insert_committed(project, empty);

  const auto stored = project.scans();
  ASSERT_EQ(stored.size(), 2u);
  EXPECT_EQ(stored[0].id, first_id);
  EXPECT_EQ(stored[1].id, empty_id);
  EXPECT_LT(first_id, empty_id);

  const acquisition::ScanSummary expected = acquisition::summarize(first);
  const acquisition::ScanSummary& got = stored[0].summary;
  EXPECT_EQ(got.name, "station 1 é");
  EXPECT_EQ(got.rows, 2);
  EXPECT_EQ(got.columns, 3);
  EXPECT_EQ(got.valid_points, 3u);
  EXPECT_TRUE(got.has_intensity);
  EXPECT_FALSE(got.has_color);
  EXPECT_TRUE(got.spherical);
  EXPECT_TRUE(test::same_bytes(Eigen::Matrix4d(got.T_world_scan.matrix()),
                               Eigen::Matrix4d(first.T_world_scan.matrix())));
  ASSERT_TRUE(got.bbox_world.has_value());
  EXPECT_EQ(got.bbox_world->min(), expected.bbox_world->min());
  EXPECT_EQ(got.bbox_world->max(), expected.bbox_world->max());
  EXPECT_EQ(got.scanner.name, "RIEGL LMS-Z360");
  EXPECT_EQ(got.scanner.source_file, first.scanner.source_file);
  EXPECT_EQ(got.scanner.position_world, first.scanner.position_world);

  EXPECT_EQ(stored[1].summary.valid_points, 0u);
  EXPECT_FALSE(stored[1].summary.bbox_world.has_value());
  EXPECT_FALSE(stored[1].summary.spherical);
  EXPECT_TRUE(stored[1].summary.has_color);
}

TEST(Project, LoadingAMissingIdIsAnInputError) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  const store::Project project = store::Project::create(file);
  try {
    project.load_scan(42);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.file(), file.string());
    EXPECT_THAT(error.what(), HasSubstr("no scan with id 42"));
  }
}

TEST(Project, AnExceptionInsideAnEditLeavesNoScanAndNoJournalEntry) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "site.sbproj");
  const auto import_then_fail = [&] {
    store::Project::Edit edit = project.begin_command("import", "{}");
    project.insert_scan(edit, store::encode_scan(tiny_scan(true, true, true)));
    throw std::runtime_error("reader failed on the second file");
  };
  EXPECT_THROW(import_then_fail(), std::runtime_error);
  EXPECT_TRUE(project.scans().empty());
  EXPECT_TRUE(project.history().empty());
  // The connection is usable again after the rollback.
  EXPECT_EQ(project.load_scan(insert_committed(project, tiny_scan(true, false, false))).rows, 2);
}

TEST(Project, TwoInsertsInOneEditAreAllOrNothing) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  store::Project project = store::Project::create(file);
  {
    store::Project::Edit edit = project.begin_command("import", "{}");
    project.insert_scan(edit, store::encode_scan(tiny_scan(true, false, false)));
    project.insert_scan(edit, store::encode_scan(tiny_scan(false, true, true)));
    EXPECT_EQ(project.scans().size(), 2u);  // visible inside the edit
  }                                         // not committed
  EXPECT_TRUE(project.scans().empty());
  EXPECT_TRUE(store::Project::open(file).scans().empty());  // nor to another connection

  store::Project::Edit edit = project.begin_command("import", "{}");
  project.insert_scan(edit, store::encode_scan(tiny_scan(true, false, false)));
  project.insert_scan(edit, store::encode_scan(tiny_scan(false, true, true)));
  edit.commit("{}");
  EXPECT_FALSE(edit.active());
  EXPECT_EQ(store::Project::open(file).scans().size(), 2u);
}

TEST(Project, MovedEditAndProjectKeepWorking) {
  const ScratchDir dir;
  store::Project original = store::Project::create(dir / "site.sbproj");
  store::Project project = std::move(original);
  store::Project::Edit first = project.begin_command("import", "{}");
  store::Project::Edit moved = std::move(first);
  EXPECT_FALSE(first.active());
  EXPECT_TRUE(moved.active());
  project.insert_scan(moved, store::encode_scan(tiny_scan(true, false, false)));
  moved.commit("{}");
  EXPECT_EQ(project.scans().size(), 1u);
}

TEST(Project, ADamagedChannelNamesTheScanAndChannel) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  std::int64_t id = 0;
  {
    store::Project project = store::Project::create(file);
    id = insert_committed(project, tiny_scan(true, true, false));
  }
  {
    RawDatabase raw(file);
    raw.execute("UPDATE scan_layers SET data = substr(data, 1, 10) WHERE name = 'intensity'");
  }
  const store::Project project = store::Project::open(file);
  EXPECT_EQ(project.scans().size(), 1u);  // summaries do not touch channel data
  try {
    project.load_scan(id);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.file(), file.string());
    EXPECT_EQ(error.position().detail, "scan " + std::to_string(id) + ", layer intensity");
  }
}

TEST(Project, AMissingChannelIsAnInputError) {
  const ScratchDir dir;
  const auto file = dir / "site.sbproj";
  std::int64_t id = 0;
  {
    store::Project project = store::Project::create(file);
    id = insert_committed(project, tiny_scan(false, false, false));
  }
  { RawDatabase(file).execute("DELETE FROM scan_layers WHERE name = 'directions'"); }
  EXPECT_THROW(store::Project::open(file).load_scan(id), core::InputError);
}

TEST(ProjectDeathTest, WritingThroughAFinishedEditIsAProgrammerError) {
#ifdef NDEBUG
  GTEST_SKIP() << "assertions are compiled out in this build";
#else
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "site.sbproj");
  store::Project::Edit edit = project.begin_command("import", "{}");
  edit.commit("{}");
  EXPECT_DEATH(project.insert_scan(edit, store::encode_scan(tiny_scan(true, false, false))),
               "writes need an open Edit of this project");
#endif
}

}  // namespace
}  // namespace scanbench::modeling

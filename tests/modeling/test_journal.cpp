// The command journal: history, undo and redo across connections, the redo
// branch, and stages as journaled commands (compute first, write after).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <thread>
#include <vector>

#include "core/errors.hpp"
#include "modeling/geometry_command.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::fixture;
using test::ScratchDir;
using ::testing::HasSubstr;

const std::vector<std::filesystem::path> kTwoScans{fixture("good/ptx/two_scans.ptx")};
const std::vector<std::filesystem::path> kTinyColor{fixture("good/ptx/tiny_color.ptx")};

acquisition::GeometrySettings small_windows() {
  acquisition::GeometrySettings settings;
  settings.window_radius = 2;
  settings.edge_window_radius = 1;
  return settings;
}

std::vector<std::string> names_and_states(const store::Project& project) {
  std::vector<std::string> out;
  for (const store::CommandRecord& c : project.history()) {
    out.push_back(c.name + (c.state == store::CommandState::kDone ? "" : " (undone)"));
  }
  return out;
}

TEST(Journal, EveryStageIsOneCommandWithItsSettingsAndResult) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  const ImportResult imported = import_scans(project, kTwoScans, {}, quiet);
  const GeometryCommandResult geometry = geometry_project(project, small_windows(), quiet);
  const std::vector<store::CommandRecord> history = project.history();
  ASSERT_EQ(history.size(), 2u);
  EXPECT_EQ(history[0].id, imported.command_id);
  EXPECT_EQ(history[0].name, "import");
  EXPECT_THAT(history[0].settings, HasSubstr("two_scans.ptx"));
  EXPECT_EQ(history[1].id, geometry.command_id);
  EXPECT_EQ(history[1].name, "geometry");
  EXPECT_THAT(history[1].settings, HasSubstr("\"window_radius\":2"));
  EXPECT_THAT(history[1].result, HasSubstr("\"mixed_pixels\""));
  EXPECT_TRUE(history[1].undoable);
  EXPECT_FALSE(history[1].created_at.empty());
}

// The check keeps the scans' compressed channels in its temporary file, not
// in memory, and the stored scans are the scans of the file.
TEST(Journal, TheImportCheckSpillsTheChannelsItKeepsAndStoresThemWhole) {
  core::Progress quiet;
  const CheckedImport checked = check_scan_files(kTwoScans, {}, quiet);
  ASSERT_EQ(checked.files.size(), 1u);
  ASSERT_EQ(checked.files[0].scans.size(), 2u);
  for (const CheckedImport::Scan& scan : checked.files[0].scans) {
    ASSERT_TRUE(scan.encoded.has_value());
    ASSERT_EQ(scan.spilled.size(), scan.encoded->layers.size());
    for (std::size_t k = 0; k < scan.spilled.size(); ++k) {
      EXPECT_TRUE(scan.encoded->layers[k].blob.empty());
      EXPECT_GT(scan.spilled[k].bytes, 0u);
    }
  }
  const ScratchDir dir;
  store::Project spilled = store::Project::create(dir / "spilled.sbproj");
  store::Project direct = store::Project::create(dir / "direct.sbproj");
  store_checked_scans(spilled, checked, {}, quiet);
  import_scans(direct, kTwoScans, {}, quiet);
  ASSERT_EQ(spilled.scans().size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const acquisition::Scan a = spilled.load_scan(spilled.scans()[k].id);
    const acquisition::Scan b = direct.load_scan(direct.scans()[k].id);
    EXPECT_EQ(a.range_m, b.range_m);
    EXPECT_EQ(a.valid, b.valid);
    EXPECT_EQ(a.intensity, b.intensity);
    EXPECT_TRUE(a.T_world_scan.isApprox(b.T_world_scan, 0.0));
  }
}

TEST(Journal, UndoAndRedoWorkAcrossConnectionsAndRestoreTheStateExactly) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  core::Progress quiet;
  {
    store::Project project = store::Project::create(file);
    import_scans(project, kTwoScans, {}, quiet);
  }
  const acquisition::Scan before = store::Project::open(file).load_scan(1);
  {
    store::Project project = store::Project::open(file);
    geometry_project(project, small_windows(), quiet);
  }
  {
    store::Project other = store::Project::open(file);  // another session
    ASSERT_TRUE(store::load_geometry(other, 1).has_value());
    const std::optional<store::CommandRecord> undone = other.undo();
    ASSERT_TRUE(undone.has_value());
    EXPECT_EQ(undone->name, "geometry");
  }
  store::Project project = store::Project::open(file);
  EXPECT_FALSE(store::load_geometry(project, 1).has_value());
  EXPECT_EQ(names_and_states(project), (std::vector<std::string>{"import", "geometry (undone)"}));
  ASSERT_TRUE(project.undo().has_value());  // the import
  EXPECT_TRUE(project.scans().empty());
  EXPECT_FALSE(project.undo().has_value());  // nothing left
  ASSERT_TRUE(project.redo().has_value());
  test::expect_identical(project.load_scan(1), before);
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_TRUE(store::load_geometry(project, 1).has_value());
  EXPECT_FALSE(project.redo().has_value());
}

// The σ(range) a geometry command used is stored with the scan's geometry
// (in the command's journal entry) and undone with it: the merge, carried
// objects and region growing read it from there.
TEST(Journal, TheGeometrysRangeNoiseComesBackWithItAndGoesWithItsUndo) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  acquisition::GeometrySettings fixed = small_windows();
  fixed.range_noise = {0.002, 1e-4, 0.0};
  geometry_project(project, fixed, quiet);
  EXPECT_EQ(store::load_geometry(project, 1)->range_noise, fixed.range_noise);
  acquisition::GeometrySettings estimating = small_windows();
  estimating.range_noise = {0.004, 0.0, 0.0};
  estimating.estimate_range_noise = true;
  const GeometryCommandResult estimated = geometry_project(project, estimating, quiet);
  for (const GeometryCommandScan& scan : estimated.scans) {
    EXPECT_EQ(store::load_geometry(project, scan.id)->range_noise, scan.range_noise) << scan.id;
  }
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(store::load_geometry(project, 2)->range_noise, fixed.range_noise);
}

TEST(Journal, ANewCommandEndsTheRedoBranch) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  geometry_project(project, small_windows(), quiet);
  project.undo();
  acquisition::GeometrySettings wider = small_windows();
  wider.window_radius = 3;
  geometry_project(project, wider, quiet);
  EXPECT_EQ(names_and_states(project), (std::vector<std::string>{"import", "geometry"}));
  EXPECT_THAT(project.history().back().settings, HasSubstr("\"window_radius\":3"));
  EXPECT_FALSE(project.redo().has_value());
  // Ids are never reused: the discarded command's id stays retired.
  EXPECT_EQ(project.history().back().id, 3);
}

TEST(Journal, ARevisionThatMovedRefusesTheWriteAndChangesNothing) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  const std::int64_t revision = project.revision();
  {
    store::Project other = store::Project::open(file);
    geometry_project(other, small_windows(), quiet);  // meanwhile, another writer
  }
  EXPECT_NE(project.revision(), revision);
  try {
    project.begin_command("merge", "{}", revision);
    FAIL() << "expected core::RuntimeFailure";
  } catch (const core::RuntimeFailure& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("the project's geometry changed while merge was computing"));
  }
  EXPECT_EQ(project.history().size(), 2u);
}

// Another process's change voids a command only where it wrote what the
// command read: a recolour (objects) lets a harmonize computed before it
// land, and an undo counts as a change of what the undone command wrote.
TEST(Journal, OnlyAChangeOfWhatACommandReadRefusesIt) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  std::int64_t revision = project.revision();
  {
    store::Project other = store::Project::open(file);
    other.begin_command("recolor", "{}").commit("{}");
    other.begin_command("measure", "{}").commit("{}");
  }
  project.begin_command("harmonize", "{}", revision).commit("{}");
  revision = project.revision();
  {
    store::Project other = store::Project::open(file);
    ASSERT_TRUE(other.undo().has_value());  // the harmonize: colour corrections change
  }
  EXPECT_NO_THROW(project.begin_command("measure", "{}", revision).commit("{}"));
  EXPECT_THROW(project.begin_command("clone", "{}", revision), core::RuntimeFailure);
  // A command scanbench does not know reads everything.
  EXPECT_THROW(project.begin_command("from the future", "{}", revision), core::RuntimeFailure);
}

// Cancels once `after` units were reported.
class CancelAfter : public core::Progress {
 public:
  explicit CancelAfter(std::size_t after) : after_(after) {}
  void update(const core::ProgressStep& step) override {
    if (step.done >= after_) request_cancel();
  }

 private:
  std::size_t after_;
};

TEST(Journal, ACancelledStageStoresNothing) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  CancelAfter cancel(1);
  EXPECT_THROW(geometry_project(project, small_windows(), cancel), core::Cancelled);
  EXPECT_EQ(project.history().size(), 1u);
  EXPECT_FALSE(store::load_geometry(project, 1).has_value());
}

TEST(Journal, ACancelledRegistrationStoresNothing) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  geometry_project(project, small_windows(), quiet);
  RegisterCommandSettings settings;
  settings.registration.coarse = registration::CoarseMethod::kNone;
  CancelAfter cancel(3);  // past loading the two scans, inside the registration
  EXPECT_THROW(register_project(project, settings, cancel), core::Cancelled);
  EXPECT_EQ(names_and_states(project), (std::vector<std::string>{"import", "geometry"}));
}

TEST(Journal, ScanIdsAreNeverReused) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  const ImportResult first = import_scans(project, kTwoScans, {}, quiet);
  project.undo();
  const ImportResult second = import_scans(project, kTwoScans, {}, quiet);  // ends the redo branch
  ASSERT_EQ(first.scan_ids.size(), 2u);
  ASSERT_EQ(second.scan_ids.size(), 2u);
  EXPECT_GT(second.scan_ids.front(), first.scan_ids.back());
  EXPECT_THROW(project.load_scan(first.scan_ids.front()), core::InputError);
}

TEST(Journal, AnImportMakesTheEarlierKeepMasksStale) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  core::Progress quiet;
  const ImportResult first = import_scans(project, kTwoScans, {}, quiet);
  const std::int64_t id = first.scan_ids.front();
  const std::vector<std::uint8_t> keep(project.load_scan(id).pixel_count(), 1);
  {
    store::Project::Edit edit = project.begin_command("merge", "{}");
    project.put_layer(
        edit, id,
        store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8, keep));
    edit.commit("{}");
  }
  import_scans(project, kTinyColor, {}, quiet);
  EXPECT_FALSE(store::load_keep_mask(project, id).has_value());
  project.undo();
  EXPECT_EQ(store::load_keep_mask(project, id), keep);
}

// Imports a scan through another connection when the first scan is done:
// another process writing while the stage computes.
class WriteMeanwhile : public core::Progress {
 public:
  explicit WriteMeanwhile(std::filesystem::path file) : file_(std::move(file)) {}
  void update(const core::ProgressStep& step) override {
    if (step.done != 1) return;
    store::Project other = store::Project::open(file_);
    core::Progress quiet;
    import_scans(other, kTinyColor, {}, quiet);
  }

 private:
  std::filesystem::path file_;
};

TEST(Journal, AStageWhoseProjectChangedMeanwhileStoresNothing) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  core::Progress quiet;
  import_scans(project, kTwoScans, {}, quiet);
  WriteMeanwhile meanwhile(file);
  try {
    geometry_project(project, small_windows(), meanwhile);
    FAIL() << "expected core::RuntimeFailure";
  } catch (const core::RuntimeFailure& error) {
    EXPECT_THAT(error.what(), HasSubstr("changed while geometry was computing"));
  }
  EXPECT_EQ(names_and_states(project), (std::vector<std::string>{"import", "import"}));
  for (const store::StoredScanSummary& stored : project.scans()) {
    EXPECT_FALSE(store::load_geometry(project, stored.id).has_value()) << stored.id;
  }
  // The written parts went with the refused command.
  EXPECT_EQ(test::RawDatabase(file).text("SELECT count(*) FROM scan_layers WHERE name = 'normal'"),
            "0");
}

TEST(Journal, UndoStopsAtAnOlderProjectsHistory) {
  const ScratchDir dir;
  const auto file = dir / "old.sbproj";
  std::filesystem::copy_file(fixture("projects/version2.sbproj"), file);
  store::Project project = store::Project::open(file);
  core::Progress quiet;
  geometry_project(project, small_windows(), quiet);
  const std::optional<store::CommandRecord> undone = project.undo();
  ASSERT_TRUE(undone.has_value());
  EXPECT_EQ(undone->name, "geometry");
  EXPECT_TRUE(undone->undoable);
  EXPECT_FALSE(project.undo().has_value());  // the migrated geometry stays
  EXPECT_TRUE(store::load_geometry(project, 1).has_value());
}

TEST(Journal, TwoProcessesMigratingOneFileAtOnceBothOpenIt) {
  const ScratchDir dir;
  const auto file = dir / "old.sbproj";
  std::filesystem::copy_file(fixture("projects/version3.sbproj"), file);
  std::vector<std::thread> openers;
  std::atomic<int> opened{0};
  for (int k = 0; k < 4; ++k) {
    openers.emplace_back([&] {
      if (store::Project::open(file).schema_version() == store::kProjectSchemaVersion) ++opened;
    });
  }
  for (std::thread& t : openers) t.join();
  EXPECT_EQ(opened.load(), 4);
  EXPECT_EQ(store::Project::open(file).history().size(), 4u);  // migrated once
}

TEST(Journal, TheMigrationOfAnOlderProjectCannotBeUndone) {
  const ScratchDir dir;
  const auto file = dir / "old.sbproj";
  std::filesystem::copy_file(fixture("projects/version1.sbproj"), file);
  store::Project project = store::Project::open(file);
  const std::vector<store::CommandRecord> history = project.history();
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0].name, "migrate");
  EXPECT_FALSE(history[0].undoable);
  EXPECT_FALSE(project.undo().has_value());
  EXPECT_EQ(project.scans().size(), 5u);
}

}  // namespace
}  // namespace scanbench::modeling

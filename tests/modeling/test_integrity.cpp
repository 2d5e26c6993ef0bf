// Checksummed records and `Project::check`: a flipped byte anywhere that
// matters is found and named; a sound project, migrated ones included,
// passes; the same data imported twice is refused unless asked for.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/errors.hpp"
#include "modeling/import_command.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::fixture;
using test::RawDatabase;
using test::ScratchDir;
using ::testing::HasSubstr;

// A project with one imported scan, closed.
std::filesystem::path sound_project(const ScratchDir& dir) {
  const auto file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  core::Progress quiet;
  import_scans(project, std::vector<std::filesystem::path>{fixture("good/ptx/tiny_color.ptx")}, {},
               quiet);
  return file;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string all;
  for (const std::string& line : lines) all += line + "\n";
  return all;
}

TEST(Integrity, ASoundProjectPassesTheCheck) {
  const ScratchDir dir;
  const store::Project project = store::Project::open(sound_project(dir));
  const store::Project::CheckReport report = project.check();
  EXPECT_TRUE(report.damage.empty()) << joined(report.damage);
  EXPECT_EQ(report.records, 4u);  // the scan, its pose, its source, the import
  EXPECT_EQ(report.layers, 4u);   // range, valid, intensity, rgb
}

TEST(Integrity, ProjectsOfEveryVersionPassTheCheck) {
  const ScratchDir dir;
  for (int version : {1, 2, 3, 4, 5, 6, 7, 8}) {
    const auto file = dir / ("v" + std::to_string(version) + ".sbproj");
    std::filesystem::copy_file(fixture("projects/version" + std::to_string(version) + ".sbproj"),
                               file);
    const store::Project::CheckReport report = store::Project::open(file).check();
    EXPECT_TRUE(report.damage.empty()) << version << ":\n" << joined(report.damage);
    EXPECT_GT(report.layers, 0u);
  }
}

TEST(Integrity, AFlippedByteInAPoseIsFoundOnReadingAndByTheCheck) {
  const ScratchDir dir;
  const auto file = sound_project(dir);
  // Flip one byte of the stored pose on disk, as a failing medium would:
  // the translation's x (row-major element 3), a byte of its mantissa.
  // tiny_color's pose is the identity.
  std::string bytes = test::read_file_bytes(file);
  const Eigen::Matrix4d m = Eigen::Isometry3d::Identity().matrix();
  std::string stored(128, '\0');
  for (int k = 0; k < 16; ++k) {
    const double value = m(k / 4, k % 4);
    std::memcpy(&stored[static_cast<std::size_t>(k) * 8], &value, 8);
  }
  const std::size_t at = bytes.find(stored);
  ASSERT_NE(at, std::string::npos);
  bytes[at + 3 * 8 + 6] ^= 0x10;  // 0.0 becomes a tiny non-zero x
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  const store::Project project = store::Project::open(file);
  try {
    project.scans();
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), HasSubstr("pose fails its checksum"));
  }
  EXPECT_THAT(joined(project.check().damage), HasSubstr("scan 1: the pose of command 1"));
}

TEST(Integrity, ChangedSettingsInTheJournalAreFound) {
  const ScratchDir dir;
  const auto file = sound_project(dir);
  RawDatabase(file).execute("UPDATE commands SET settings = replace(settings, 'tiny', 'tidy')");
  const store::Project project = store::Project::open(file);
  EXPECT_THROW(project.history(), core::InputError);
  EXPECT_THAT(joined(project.check().damage), HasSubstr("command 1 (import)"));
}

TEST(Integrity, ChangedSourcesAndImagesAreFound) {
  const ScratchDir dir;
  const auto file = dir / "images.sbproj";
  std::filesystem::copy_file(fixture("projects/version7.sbproj"), file);
  RawDatabase(file).execute(
      "UPDATE scan_sources SET details = replace(details, 'structured', 'structures')");
  RawDatabase(file).execute("UPDATE scan_images SET data = zeroblob(length(data)) WHERE id = 2");
  RawDatabase(file).execute("UPDATE scan_images SET format = 'jpeg' WHERE id = 1");
  const store::Project project = store::Project::open(file);
  EXPECT_THROW(project.scan_sources(), core::InputError);
  EXPECT_THROW(project.images(false), core::InputError);
  const std::string damage = joined(project.check().damage);
  EXPECT_THAT(damage, HasSubstr("source of scan 4 fails its checksum"));
  EXPECT_THAT(damage, HasSubstr("image 1 fails its checksum"));
  EXPECT_THAT(damage, HasSubstr("image 2: its data fails its CRC"));
}

TEST(Integrity, ChangedColourEditsAndCorrectionsAreFound) {
  const ScratchDir dir;
  const auto file = sound_project(dir);
  {
    store::Project project = store::Project::open(file);
    store::ObjectNode node;
    node.id = project.new_node_id();
    node.name = "wall";
    node.color.hue_deg = 30.0;
    store::Project::Edit edit = project.begin_command("recolor", "{}");
    project.put_node(edit, node);
    store::ScanColorCorrection gains;
    gains.matrix.diagonal() << 1.1, 1.0, 0.9;
    project.put_scan_color_correction(edit, project.scans().front().id, gains);
    edit.commit("{}");
  }
  RawDatabase(file).execute("UPDATE object_nodes SET color_edit = '{\"hue_deg\": 90.0}'");
  RawDatabase(file).execute(
      "UPDATE scan_colors SET correction = replace(correction, '1.1', '1.2')");
  const store::Project project = store::Project::open(file);
  try {
    project.object_nodes();
    ADD_FAILURE() << "a changed colour edit was read";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), HasSubstr("checksum"));
    EXPECT_THAT(error.position().detail, HasSubstr("object node"));
  }
  try {
    project.scan_color_corrections();
    ADD_FAILURE() << "a changed colour correction was read";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), HasSubstr("checksum"));
    EXPECT_THAT(error.position().detail, HasSubstr("colour correction of scan 1"));
  }
  const std::string damage = joined(project.check().damage);
  EXPECT_THAT(damage, HasSubstr("object node"));
  EXPECT_THAT(damage, HasSubstr("colour correction of scan 1"));
}

TEST(Integrity, ADamagedLayerIsNamedByTheCheck) {
  const ScratchDir dir;
  const auto file = sound_project(dir);
  RawDatabase(file).execute(
      "UPDATE scan_layers SET data = substr(data, 1, 12) || x'00' || substr(data, 14) "
      "WHERE name = 'intensity'");
  const store::Project::CheckReport report = store::Project::open(file).check();
  ASSERT_EQ(report.damage.size(), 1u) << joined(report.damage);
  EXPECT_THAT(report.damage[0], HasSubstr("scan 1, layer intensity of command 1"));
}

TEST(Integrity, AChangedLayerRowIsFoundOnReadingAndByTheCheck) {
  const ScratchDir dir;
  const auto file = sound_project(dir);
  // The data still decodes; the row now claims another layer's name.
  RawDatabase(file).execute("UPDATE scan_layers SET name = 'intensitx' WHERE name = 'intensity'");
  const store::Project project = store::Project::open(file);
  EXPECT_THROW(project.load_scan(1), core::InputError);
  const store::Project::CheckReport report = project.check();
  ASSERT_EQ(report.damage.size(), 1u) << joined(report.damage);
  EXPECT_THAT(report.damage[0], HasSubstr("layer intensitx of command 1: its row"));
}

// Two versions of one node, of one layer and of a pose: command 2 writes
// the first, command 3 the second. Returns the project's file.
std::filesystem::path two_versions(const ScratchDir& dir) {
  const auto file = sound_project(dir);
  store::Project project = store::Project::open(file);
  const std::int64_t scan = project.scans().front().id;
  const std::size_t pixels = project.load_scan(scan).pixel_count();
  for (const char* name : {"wall", "north wall"}) {
    store::ObjectNode node;
    node.id = 1;
    node.name = name;
    store::Project::Edit edit = project.begin_command("edit", "{}");
    project.put_node(edit, node);
    project.put_layer(
        edit, scan,
        store::encode_layer<std::uint8_t>("selection", store::ElementType::kU8,
                                          std::vector<std::uint8_t>(pixels, name[0])));
    acquisition::Scan moved = project.load_scan(scan);
    moved.T_world_scan.translation().x() += 1.0;
    project.set_pose(edit, scan, moved);
    edit.commit("{}");
  }
  return file;
}

std::string journal_of(const store::Project& project) {
  std::string out;
  for (const store::CommandRecord& c : project.history())
    out += std::to_string(c.id) + ":" + std::to_string(static_cast<int>(c.state)) + " ";
  return out;
}

TEST(Integrity, UndoAndRedoRefuseToMakeADamagedVersionCurrent) {
  const ScratchDir dir;
  const auto file = two_versions(dir);
  // The older node version is damaged: undoing command 3 would make it current.
  RawDatabase(file).execute("UPDATE object_nodes SET name = 'wal' WHERE command_id = 2");
  {
    store::Project project = store::Project::open(file);
    const std::string journal = journal_of(project);
    try {
      project.undo();
      ADD_FAILURE() << "undo made a damaged node current";
    } catch (const core::InputError& error) {
      EXPECT_THAT(error.problem(), HasSubstr("checksum"));
      EXPECT_THAT(error.position().detail, HasSubstr("object node 1"));
    }
    EXPECT_EQ(journal_of(project), journal);
    EXPECT_EQ(project.object_nodes().front().name, "north wall");
  }
  RawDatabase(file).execute("UPDATE object_nodes SET name = 'wall' WHERE command_id = 2");
  // The older pose is damaged.
  RawDatabase(file).execute("UPDATE scan_poses SET scanner_z = scanner_z + 1 WHERE command_id = 2");
  {
    store::Project project = store::Project::open(file);
    const std::string journal = journal_of(project);
    try {
      project.undo();
      ADD_FAILURE() << "undo made a damaged pose current";
    } catch (const core::InputError& error) {
      EXPECT_THAT(error.problem(), HasSubstr("pose fails its checksum"));
    }
    EXPECT_EQ(journal_of(project), journal);
  }
  RawDatabase(file).execute("UPDATE scan_poses SET scanner_z = scanner_z - 1 WHERE command_id = 2");
  // The newer version is undone, then its layer's data damaged: redo would
  // make it current.
  {
    store::Project project = store::Project::open(file);
    ASSERT_TRUE(project.undo());
  }
  RawDatabase(file).execute(
      "UPDATE scan_layers SET data = substr(data, 1, 12) || x'ff' || substr(data, 14) "
      "WHERE command_id = 3");
  store::Project project = store::Project::open(file);
  const std::string journal = journal_of(project);
  try {
    project.redo();
    ADD_FAILURE() << "redo made a damaged layer current";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.position().detail, HasSubstr("layer selection"));
  }
  EXPECT_EQ(journal_of(project), journal);
}

TEST(Integrity, TheCheckNeverChangesTheFileItChecks) {
  const ScratchDir dir;
  const auto old = dir / "v2.sbproj";
  std::filesystem::copy_file(fixture("projects/version2.sbproj"), old);
  const std::string before = test::read_file_bytes(old);
  try {
    store::Project::open_read_only(old);
    FAIL() << "expected core::RuntimeFailure";
  } catch (const core::RuntimeFailure& error) {
    EXPECT_THAT(error.problem(), HasSubstr("schema version 2, read here without changes"));
  }
  EXPECT_EQ(test::read_file_bytes(old), before);
  const store::Project project = store::Project::open_read_only(sound_project(dir));
  EXPECT_TRUE(project.check().damage.empty());
}

TEST(Integrity, TheSameScanImportedTwiceIsRefusedUnlessAllowed) {
  const ScratchDir dir;
  store::Project project = store::Project::open(sound_project(dir));
  core::Progress quiet;
  const std::vector<std::filesystem::path> again{fixture("good/ptx/tiny_color.ptx")};
  try {
    import_scans(project, again, {}, quiet);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), HasSubstr("already in the project as scan 1"));
  }
  EXPECT_EQ(project.scans().size(), 1u);
  // The same file twice in one call is a twin too.
  const auto copy = dir / "copy.ptx";
  std::filesystem::copy_file(fixture("good/ptx/two_scans.ptx"), copy);
  const std::vector<std::filesystem::path> twice{fixture("good/ptx/two_scans.ptx"), copy};
  EXPECT_THROW(import_scans(project, twice, {}, quiet), core::InputError);
  EXPECT_EQ(project.scans().size(), 1u);
  ImportSettings allow;
  allow.allow_duplicates = true;
  import_scans(project, again, allow, quiet);
  EXPECT_EQ(project.scans().size(), 2u);
}

}  // namespace
}  // namespace scanbench::modeling

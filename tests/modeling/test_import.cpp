#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "core/process.hpp"
#include "modeling/import_command.hpp"
#include "modeling/project_test_support.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::fixture;
using test::import_files;
using test::ScratchDir;

std::vector<std::string> scan_names(const std::filesystem::path& project) {
  std::vector<std::string> names;
  for (const auto& stored : store::Project::open(project).scans())
    names.push_back(stored.summary.name);
  return names;
}

TEST(ImportScans, AllFilesOfOneCallLandTogether) {
  ScratchDir dir;
  const std::vector<std::filesystem::path> files{fixture("good/ptx/two_scans.ptx"),
                                                 fixture("good/ptx/tiny_color.ptx")};
  const ImportResult result = import_files(dir / "p.sbproj", files);
  EXPECT_TRUE(result.created_project);
  EXPECT_EQ(result.scan_ids.size(), 3u);
  EXPECT_EQ(scan_names(dir / "p.sbproj"),
            (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color"}));
}

TEST(ImportScans, ABadFileRollsBackTheWholeCall) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  import_files(project, {fixture("good/ptx/tiny_color.ptx")});
  const std::vector<std::filesystem::path> files{fixture("good/ptx/two_scans.ptx"),
                                                 fixture("bad/ptx_color_out_of_range.ptx")};
  EXPECT_THROW(import_files(project, files), core::InputError);
  EXPECT_EQ(store::Project::open(project).history().size(), 1u);
  EXPECT_EQ(scan_names(project), std::vector<std::string>{"tiny_color"});
}

// An ASCII PLY of 100 points scattered over a cube of side `extent_m`
// around the origin, and, `apart_m` along x, 100 more.
void write_cloud_ply(const std::filesystem::path& path, double extent_m, double apart_m = 0.0) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat ascii 1.0\nelement vertex 200\nproperty double x\n"
         "property double y\nproperty double z\nend_header\n";
  for (int k = 0; k < 200; ++k) {
    const auto coordinate = [&](double phase) {
      return extent_m * (std::fmod(k * 0.6180339887 + phase, 1.0) - 0.5);
    };
    char line[96];
    std::snprintf(line, sizeof line, "%.4f %.4f %.4f\n",
                  coordinate(0.1) + (k % 2 == 1 ? apart_m : 0.0), coordinate(0.37),
                  coordinate(0.73));
    out << line;
  }
}

TEST(ImportScans, ACloudTooWideForFloatRangesIsTiledAndKeepsATenthOfAMillimetre) {
  // Points 5 km apart cannot all come back within 0.1 mm from float ranges
  // around one centre (a float range errs by up to 0.15 mm at 2.5 km): the
  // cloud becomes one scan per 400 m cube it touches; 30 m apart, one scan.
  ScratchDir dir;
  write_cloud_ply(dir / "wide.ply", 30.0, 5000.0);
  write_cloud_ply(dir / "near.ply", 30.0);
  const ImportResult result = import_files(dir / "p.sbproj", {dir / "wide.ply", dir / "near.ply"});
  EXPECT_TRUE(result.beyond_promise.empty());
  ASSERT_EQ(result.scan_ids.size(), 3u);
  const store::Project project = store::Project::open(dir / "p.sbproj");
  const auto sources = project.scan_sources();
  std::vector<std::string> names;
  for (const store::StoredScanSummary& stored : project.scans()) {
    names.push_back(stored.summary.name);
    EXPECT_EQ(stored.summary.valid_points, stored.id == result.scan_ids[2] ? 200u : 100u);
    EXPECT_EQ(sources.at(stored.id).points_in_file, stored.summary.valid_points);
    EXPECT_LE(sources.at(stored.id).round_trip_error_m, acquisition::kPromisedRoundTripM);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"wide-1", "wide-2", "near"}));
}

// Blocks the import once its first file is stored (after every file was
// checked), its two scans written as committed parts of a pending command:
// a kill there must leave the project as it was, and the next writer must
// clear what the dead import left.
class PauseAfterFirstFile : public core::Progress {
 public:
  explicit PauseAfterFirstFile(int report_fd) : report_fd_(report_fd) {}
  void update(const core::ProgressStep& step) override {
    if (step.done <= step.total / 2) return;  // still checking
    const char read = 'r';
    if (::write(report_fd_, &read, 1) != 1) ::_exit(3);
    ::pause();  // wait here for the kill
  }

 private:
  int report_fd_;
};

TEST(ImportScans, KillDuringImportLeavesProjectAsBefore) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  import_files(project, {fixture("good/ptx/tiny_color.ptx")});
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(pipe_fds[0]);
    PauseAfterFirstFile pause(pipe_fds[1]);
    import_scan_files(project,
                      std::vector<std::filesystem::path>{fixture("good/ptx/two_scans.ptx"),
                                                         fixture("good/ptx/georef_world_1e5.ptx")},
                      {}, pause);
    ::_exit(4);  // never reached: the parent kills us first
  }
  ::close(pipe_fds[1]);
  char signal_byte = 0;
  ASSERT_EQ(::read(pipe_fds[0], &signal_byte, 1), 1);
  ::close(pipe_fds[0]);
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(scan_names(project), std::vector<std::string>{"tiny_color"});
  const acquisition::Scan kept =
      store::Project::open(project).load_scan(store::Project::open(project).scans()[0].id);
  EXPECT_EQ(kept.rows, 2);
  // The dead import's committed parts are there but invisible ...
  const auto raw_count = [&] {
    return test::RawDatabase(project).text("SELECT count(*) FROM scans");
  };
  EXPECT_EQ(raw_count(), "3");
  // History shows the dead writer's command as interrupted, not pending.
  EXPECT_EQ(store::Project::open(project).history().back().state,
            store::CommandState::kInterrupted);
  // ... until the next writer removes them.
  import_files(project, {fixture("good/ptx/irregular.ptx")});
  EXPECT_EQ(raw_count(), "2");
  for (const store::CommandRecord& c : store::Project::open(project).history()) {
    EXPECT_EQ(c.state, store::CommandState::kDone) << c.id;
  }
}

// Pending commands another process left: removed when that process is
// gone on this machine (its pid now names a process started at another
// time), kept when it runs on another machine, where nothing can tell.
TEST(ImportScans, OnlyPendingCommandsOfGoneProcessesOfThisMachineAreRemoved) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  import_files(project, {fixture("good/ptx/tiny_color.ptx")});
  const core::ProcessIdentity self = core::this_process();
  {
    test::RawDatabase raw(project);
    const auto pending = [&](const std::string& machine, std::int64_t start) {
      raw.execute(
          "INSERT INTO commands (name, settings, state, undoable, owner_machine, "
          "owner_pid, owner_start) VALUES ('import', '{}', 'pending', 1, '" +
          machine + "', " + std::to_string(self.pid) + ", " + std::to_string(start) + ")");
    };
    pending(self.machine, self.start_ticks + 1);                            // a reused pid: gone
    pending("survey-laptop boot 1234 pid:[4026531836]", self.start_ticks);  // elsewhere
  }
  import_files(project, {fixture("good/ptx/irregular.ptx")});
  EXPECT_EQ(test::RawDatabase(project).text(
                "SELECT group_concat(owner_machine) FROM commands WHERE state = 'pending'"),
            "survey-laptop boot 1234 pid:[4026531836]");
}

}  // namespace
}  // namespace scanbench::modeling

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <vector>

#include "core/errors.hpp"
#include "modeling/import_scans.hpp"
#include "modeling/project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::fixture;
using test::ScratchDir;

std::vector<std::string> scan_names(const std::filesystem::path& project) {
  std::vector<std::string> names;
  for (const auto& stored : Project::open(project).scans()) names.push_back(stored.summary.name);
  return names;
}

TEST(ImportScans, AllFilesOfOneCallLandTogether) {
  ScratchDir dir;
  const std::vector<std::filesystem::path> files{fixture("good/ptx/two_scans.ptx"),
                                                 fixture("good/ptx/tiny_color.ptx")};
  const ImportResult result = import_scan_files(dir / "p.sbproj", files);
  EXPECT_TRUE(result.created_project);
  EXPECT_EQ(result.scan_ids.size(), 3u);
  EXPECT_EQ(scan_names(dir / "p.sbproj"),
            (std::vector<std::string>{"two_scans", "two_scans-2", "tiny_color"}));
}

TEST(ImportScans, ABadFileRollsBackTheWholeCall) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  import_scan_files(project,
                    std::vector<std::filesystem::path>{fixture("good/ptx/tiny_color.ptx")});
  const std::vector<std::filesystem::path> files{fixture("good/ptx/two_scans.ptx"),
                                                 fixture("bad/ptx_color_out_of_range.ptx")};
  EXPECT_THROW(import_scan_files(project, files), core::InputError);
  EXPECT_EQ(scan_names(project), std::vector<std::string>{"tiny_color"});
}

// A SIGKILL while the import transaction is open (one of two scans stored)
// must leave the project exactly as it was before the import began.
TEST(ImportScans, KillDuringImportLeavesProjectAsBefore) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  import_scan_files(project,
                    std::vector<std::filesystem::path>{fixture("good/ptx/tiny_color.ptx")});
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(pipe_fds[0]);
    ImportSettings settings;
    settings.on_scan_stored = [&](const ImportProgress&) {
      const char stored = 's';
      if (::write(pipe_fds[1], &stored, 1) != 1) ::_exit(3);
      ::pause();  // wait here, mid-transaction, for the kill
    };
    import_scan_files(
        project, std::vector<std::filesystem::path>{fixture("good/ptx/two_scans.ptx")}, settings);
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
      Project::open(project).load_scan(Project::open(project).scans()[0].id);
  EXPECT_EQ(kept.rows, 2);
}

}  // namespace
}  // namespace scanbench::modeling

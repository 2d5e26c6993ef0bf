// What a hostile user found, each as it was reproduced: an export over its
// own project, non-UTF-8 names, a FIFO, exit codes that lied, partial
// outputs, a header that asks for 128 GB, two imports creating one project.
// Each runs the scanbench executable as a user would.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli_runner.hpp"
#include "modeling/store/project.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

using test::CliResult;
using test::fixture;
using test::run_cli;
using test::ScratchDir;
using test::shell_quote;

using test::expect_one_line_error;
using test::make_project;
using test::run_shell;

TEST(Robustness, AnExportNeverReplacesItsProjectOrAnyProject) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj", other = dir / "other.sbproj";
  const std::string before = make_project(dir, project);
  make_project(dir, other);
  std::filesystem::create_symlink(project, dir / "link.sbproj");
  std::filesystem::create_hard_link(project, dir / "hard.sbproj");
  const std::string dotted = (dir.path() / "." / "p.sbproj").string();
  for (const std::string& output :
       {project.string(), dotted, (dir / "link.sbproj").string(), (dir / "hard.sbproj").string()}) {
    const CliResult result =
        run_cli(dir, {"export", project.string(), "--format", "ply", "-o", output});
    expect_one_line_error(result, 2, "never replaces its input");
  }
  expect_one_line_error(
      run_cli(dir, {"export", project.string(), "--format", "csv", "-o", other.string()}), 2,
      "scanbench never writes over a project");
  EXPECT_EQ(run_cli(dir, {"info", project.string(), "--json"}).out, before);
  EXPECT_EQ(run_cli(dir, {"info", other.string(), "--json"}).exit_code, 0);
}

TEST(Robustness, AnExportToAFolderToNothingOrIntoNoFolderIsBadInput) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  std::filesystem::create_directory(dir / "folder");
  expect_one_line_error(run_cli(dir, {"export", project.string(), "--format", "ply", "-o",
                                      (dir / "folder").string()}),
                        2, "is a directory");
  expect_one_line_error(run_cli(dir, {"export", project.string(), "--format", "ply", "-o", ""}), 2,
                        "no output file given");
  expect_one_line_error(run_cli(dir, {"export", project.string(), "--format", "ply", "-o",
                                      (dir / "missing/p.ply").string()}),
                        2,
                        "its folder " + (dir / "missing").string() + " is not an existing folder");
}

TEST(Robustness, NamesThatAreNotUtf8KeepEveryJsonReportValid) {
  ScratchDir dir;
  const std::filesystem::path bad = dir / "\xff\xfe_bad.ptx";
  std::filesystem::copy_file(fixture("good/ptx/two_scans.ptx"), bad);
  const std::string project = (dir / "p.sbproj").string();
  ASSERT_EQ(run_cli(dir, {"import", project, bad.string()}).exit_code, 0);
  ASSERT_EQ(run_cli(dir, {"geometry", project, "--window", "2", "--edge-window", "1"}).exit_code,
            0);
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"info", project, "--json"},
        std::vector<std::string>{"merge", project, "--json"},
        std::vector<std::string>{"history", project, "--json"}}) {
    const CliResult result = run_cli(dir, command);
    ASSERT_EQ(result.exit_code, 0) << command[0] << ": " << result.err;
    EXPECT_TRUE(nlohmann::json::accept(result.out)) << command[0] << ": " << result.out;
  }
  // Two scans of 2 × 2 points: no pair registers, a failure in one line
  // (naming the scans by id), with nothing printed on stdout.
  const CliResult registered = run_cli(dir, {"register", project, "--coarse", "none", "--json"});
  EXPECT_EQ(registered.exit_code, 1) << registered.err;
  EXPECT_EQ(std::count(registered.err.begin(), registered.err.end(), '\n'), 1) << registered.err;
  EXPECT_EQ(registered.out, "");
}

// The decoder's reason is part of our one line; nothing else is printed.
TEST(Robustness, ADamagedImageGivesOneLineWithTheDecodersReason) {
  ScratchDir dir;
  const CliResult result =
      run_cli(dir, {"import", (dir / "p.sbproj").string(),
                    fixture("bad/triplet_image_corrupt_png/scan.json").string()});
  expect_one_line_error(result, 2, "unreadable or corrupt (libpng:");
}

TEST(Robustness, APipeIsRefusedAtOnceAndLeavesNoProject) {
  ScratchDir dir;
  const std::filesystem::path fifo = dir / "scan.ptx";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const CliResult result = run_shell(dir, "timeout 20 \"$SCANBENCH\" import " +
                                              shell_quote((dir / "new.sbproj").string()) + " " +
                                              shell_quote(fifo.string()));
  expect_one_line_error(result, 2, "not a regular file");
  EXPECT_FALSE(std::filesystem::exists(dir / "new.sbproj"));
}

// RLIMIT_FSIZE makes writes past a size fail as a full disk does (EFBIG).
TEST(Robustness, AFullDiskIsARuntimeFailureAndChangesNothing) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  const std::string before = make_project(dir, project);
  ASSERT_EQ(run_cli(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(),
                          "--scans", "1", "--columns", "720", "--rows", "180"})
                .exit_code,
            0);
  const std::string limited = "trap '' XFSZ; ulimit -f 256; exec \"$SCANBENCH\" ";
  const CliResult import =
      run_shell(dir, limited + "import " + shell_quote(project.string()) + " " +
                         shell_quote((dir / "sim/campus_scan_01.json").string()));
  expect_one_line_error(import, 1, "p.sbproj");
  EXPECT_EQ(run_cli(dir, {"info", project.string(), "--json"}).out, before);
  // A triplet export that does not fit leaves none of its files behind.
  ASSERT_EQ(run_cli(dir, {"import", project.string(), (dir / "sim/campus_scan_01.json").string()})
                .exit_code,
            0);
  std::filesystem::create_directory(dir / "out");
  const CliResult triplet =
      run_shell(dir, "trap '' XFSZ; ulimit -f 64; exec \"$SCANBENCH\" export " +
                         shell_quote(project.string()) + " --format triplet --scan 2 -o " +
                         shell_quote((dir / "out/t.json").string()));
  expect_one_line_error(triplet, 1, "cannot write");
  EXPECT_TRUE(std::filesystem::is_empty(dir / "out"));
}

TEST(Robustness, TheNextRunOfAnExportRemovesWhatAKilledOneLeft) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const std::filesystem::path csv = dir / "points.csv";
  // A process that is gone: its pid names what its killed export left.
  const pid_t gone = ::fork();
  if (gone == 0) ::_exit(0);
  ASSERT_GT(gone, 0);
  ::waitpid(gone, nullptr, 0);
  const std::string left = csv.string() + ".partial-" + std::to_string(gone);
  { std::ofstream(left) << "half of an earlier, killed export"; }
  ASSERT_EQ(
      run_cli(dir, {"export", project.string(), "--format", "csv", "-o", csv.string()}).exit_code,
      0);
  EXPECT_FALSE(std::filesystem::exists(left));
  EXPECT_TRUE(std::filesystem::exists(csv));
}

// Another user, who may read the project but not write it or its folder (a
// write-protected USB stick on site), can still describe and export it.
TEST(Robustness, AReadOnlyProjectCanBeDescribedAndExported) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run commands as another user";
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  const std::string before = make_project(dir, project);
  std::filesystem::create_directory(dir / "out");
  ::chmod((dir / "out").c_str(), 0777);
  const std::string as_nobody =
      "exec setpriv --reuid=65534 --regid=65534 --clear-groups \"$SCANBENCH\" ";
  const CliResult info =
      run_shell(dir, as_nobody + "info " + shell_quote(project.string()) + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(info.out, before);
  const CliResult exported =
      run_shell(dir, as_nobody + "export " + shell_quote(project.string()) + " --format csv -o " +
                         shell_quote((dir / "out/p.csv").string()));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_EQ(run_shell(dir, as_nobody + "history " + shell_quote(project.string())).exit_code, 0);
  // Writing is a runtime failure, not bad input, and changes nothing.
  const CliResult write = run_shell(dir, as_nobody + "geometry " + shell_quote(project.string()));
  EXPECT_EQ(write.exit_code, 1) << write.err;
  EXPECT_EQ(run_cli(dir, {"info", project.string(), "--json"}).out, before);
}

// A project copied to a write-protected medium with its write-ahead log
// holding changes, and without the log's shared-memory file: SQLite cannot
// read the log safely, and reading the file alone would show an older state.
TEST(Robustness, AReadOnlyProjectWhoseLogHoldsChangesIsRefusedWithTheReason) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run commands as another user";
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  // A writer that ends without closing: its undo stays in the log.
  const pid_t writer = ::fork();
  if (writer == 0) {
    try {
      store::Project open = store::Project::open(project);
      ::_exit(open.undo() ? 0 : 1);
    } catch (...) {
      ::_exit(2);
    }
  }
  ASSERT_GT(writer, 0);
  int status = 0;
  ::waitpid(writer, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  const std::filesystem::path log = project.string() + "-wal";
  ASSERT_GT(std::filesystem::file_size(log), 0u);
  std::filesystem::remove(project.string() + "-shm");
  const std::string before = test::read_file_bytes(project);
  const CliResult info =
      run_shell(dir,
                "exec setpriv --reuid=65534 --regid=65534 --clear-groups \"$SCANBENCH\" "
                "info " +
                    shell_quote(project.string()));
  expect_one_line_error(info, 1, "its write-ahead log holds changes and the folder is read-only");
  EXPECT_EQ(test::read_file_bytes(project), before);
  // Where it can be written, the undo in the log is there.
  const CliResult history = run_cli(dir, {"history", project.string()});
  ASSERT_EQ(history.exit_code, 0) << history.err;
  EXPECT_NE(history.out.find("undone"), std::string::npos) << history.out;
}

TEST(Robustness, CheckNamesDamageAndTheSameFileTwiceIsRefused) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  const std::string before = make_project(dir, project);
  const CliResult sound = run_cli(dir, {"check", project.string()});
  EXPECT_EQ(sound.exit_code, 0) << sound.err;
  EXPECT_NE(sound.out.find(": ok ("), std::string::npos) << sound.out;
  expect_one_line_error(
      run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()}), 2,
      "already in the project as scan 1");
  EXPECT_EQ(run_cli(dir, {"info", project.string(), "--json"}).out, before);
  EXPECT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string(),
                          "--allow-duplicate"})
                .exit_code,
            0);
  // The file name, in the scan record and the journal entry: both named on
  // stdout, exit 2.
  {
    std::string bytes = test::read_file_bytes(project);
    std::size_t flipped = 0;
    for (std::size_t at = bytes.find("tiny_color.ptx"); at != std::string::npos;
         at = bytes.find("tiny_color.ptx", at + 1), ++flipped) {
      bytes[at] = 'T';
    }
    ASSERT_GT(flipped, 0u);
    std::ofstream(project, std::ios::binary | std::ios::trunc) << bytes;
  }
  const CliResult damaged = run_cli(dir, {"check", project.string()});
  expect_one_line_error(damaged, 2, "project is damaged");
  EXPECT_NE(damaged.out.find("damaged: scan 1: its record"), std::string::npos) << damaged.out;
  EXPECT_NE(damaged.out.find("damaged: command 1 (import): its journal entry"), std::string::npos)
      << damaged.out;
}

TEST(Robustness, TwoImportsCreatingOneProjectAtOnceBothLand) {
  ScratchDir dir;
  const std::string project = shell_quote((dir / "new.sbproj").string());
  const std::string first = shell_quote(fixture("good/ptx/tiny_color.ptx").string());
  const std::string second = shell_quote(fixture("good/ptx/two_scans.ptx").string());
  const CliResult both = run_shell(dir, "\"$SCANBENCH\" import " + project + " " + first +
                                            " & \"$SCANBENCH\" import " + project + " " + second +
                                            " & wait %1 && wait %2");
  ASSERT_EQ(both.exit_code, 0) << both.err;
  const CliResult info = run_cli(dir, {"info", (dir / "new.sbproj").string(), "--json"});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out)["scans"].size(), 3u);
}

}  // namespace
}  // namespace scanbench

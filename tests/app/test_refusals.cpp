// The second hostile trial's findings, each reproduced as it was found:
// thread counts that crashed, exports over the project's own source scans,
// numbers too large for a double, view and replay files that wrapped their
// integers, names with control characters, refused imports that still
// changed the file, and messages that named no file. Each runs the
// scanbench executable as a user would.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

using test::CliResult;
using test::expect_one_line_error;
using test::fixture;
using test::make_project;
using test::run_cli;
using test::ScratchDir;
using ::testing::HasSubstr;
using ::testing::Not;

std::filesystem::path write_text(const ScratchDir& dir, const std::string& name,
                                 const std::string& text) {
  const std::filesystem::path file = dir / name;
  std::ofstream(file, std::ios::binary) << text;
  return file;
}

TEST(Refusals, ThreadCountsOutsideTheirRangeAreUsageErrorsAndLargeOnesRunQuietly) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const std::string before = test::read_file_bytes(project);
  for (const char* threads : {"70000", "-5", "1025", "many"}) {
    for (const char* command : {"geometry", "register", "merge", "harmonize"}) {
      const CliResult run = run_cli(dir, {command, project.string(), "--threads", threads});
      expect_one_line_error(run, 2, "--threads");
    }
    const CliResult simulate = run_cli(dir, {"simulate", "--site", "street", "--out",
                                             (dir / "sim").string(), "--threads", threads});
    expect_one_line_error(simulate, 2, "--threads");
  }
  EXPECT_EQ(test::read_file_bytes(project), before);
  // More than the cores: as many as there are, and no library's warning.
  const CliResult geometry = run_cli(dir, {"geometry", project.string(), "--threads", "1024"});
  EXPECT_EQ(geometry.exit_code, 0) << geometry.err;
  EXPECT_EQ(geometry.err, "");
}

TEST(Refusals, AnExportNeverReplacesTheFilesTheProjectWasImportedFrom) {
  ScratchDir dir;
  const std::filesystem::path source = dir / "station.ptx", project = dir / "p.sbproj";
  std::filesystem::copy_file(fixture("good/ptx/tiny_color.ptx"), source);
  ASSERT_EQ(run_cli(dir, {"import", project.string(), source.string()}).exit_code, 0);
  const std::string scan = test::read_file_bytes(source);
  std::filesystem::create_symlink(source, dir / "link.ptx");
  std::filesystem::create_hard_link(source, dir / "hard.e57");
  for (const std::filesystem::path& output : {source, dir / "link.ptx", dir / "hard.e57"}) {
    for (const bool force : {false, true}) {
      std::vector<std::string> args = {"export", project.string(), "--format", "ply",
                                       "-o",     output.string()};
      if (force) args.push_back("--force");
      expect_one_line_error(run_cli(dir, args), 2, "imported from");
    }
  }
  // Renamed since the import: still the same file.
  std::filesystem::rename(source, dir / "moved.ptx");
  expect_one_line_error(run_cli(dir, {"export", project.string(), "--format", "ptx", "-o",
                                      (dir / "moved.ptx").string(), "--force"}),
                        2, "imported from");
  EXPECT_EQ(test::read_file_bytes(dir / "moved.ptx"), scan);
  // Any other existing file needs --force.
  const std::filesystem::path notes = write_text(dir, "notes.csv", "keep me");
  expect_one_line_error(
      run_cli(dir, {"export", project.string(), "--format", "csv", "-o", notes.string()}), 2,
      "exists; --force replaces it");
  EXPECT_EQ(test::read_file_bytes(notes), "keep me");
  EXPECT_EQ(
      run_cli(dir, {"export", project.string(), "--format", "csv", "-o", notes.string(), "--force"})
          .exit_code,
      0);
  EXPECT_NE(test::read_file_bytes(notes), "keep me");
}

TEST(Refusals, ATripletsImagesAndAnOlderProjectsRelativeSourcesAreNeverReplaced) {
  ScratchDir dir;
  for (const char* name :
       {"small.json", "small_range.png", "small_intensity.png", "small_color.png"})
    std::filesystem::copy_file(fixture(std::string("good/triplet/") + name), dir / name);
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), (dir / "small.json").string()}).exit_code, 0);
  for (const char* image : {"small_range.png", "small_intensity.png", "small_color.png"}) {
    expect_one_line_error(run_cli(dir, {"export", project.string(), "--format", "ply", "-o",
                                        (dir / image).string(), "--force"}),
                          2, "imported from");
  }
  // A project of schema 7 recorded its E57 scan's file as typed, relative
  // to the folder it was imported from: taken from the project's folder too.
  const std::filesystem::path old = dir / "old" / "version7.sbproj";
  const std::filesystem::path source = dir / "old/fixtures/good/e57/structured_spherical.e57";
  std::filesystem::create_directories(source.parent_path());
  std::filesystem::copy_file(fixture("projects/version7.sbproj"), old);
  std::filesystem::copy_file(fixture("good/e57/structured_spherical.e57"), source);
  const std::string bytes = test::read_file_bytes(source);
  expect_one_line_error(run_cli(dir, {"export", old.string(), "--format", "e57", "--scan", "4",
                                      "-o", source.string(), "--force"}),
                        2, "is a file scan 4 was imported from");
  EXPECT_EQ(test::read_file_bytes(source), bytes);
}

TEST(Refusals, NumbersTooLargeForADoubleAreBadInputNamingTheFileAndLine) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const std::filesystem::path view =
      write_text(dir, "view.json",
                 "{\"width\": 64, \"height\": 48,\n \"vertical_fov_deg\": 1e400,\n"
                 " \"position\": [1, 0, 0], \"look_at\": [0, 0, 0]}");
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"render", project.string(), "--view", view.string(), "-o",
                                 (dir / "a.png").string()},
        std::vector<std::string>{"simulate", "--site", "street", "--out", (dir / "sim").string(),
                                 "--render-view", view.string(), "-o", (dir / "b.png").string()}}) {
    const CliResult run = run_cli(dir, args);
    expect_one_line_error(run, 2, "view.json: line 2");
    EXPECT_THAT(run.err, Not(HasSubstr("json.exception")));
  }
  const std::filesystem::path script = write_text(
      dir, "ops.json", R"({"ops": [{"op": "grow", "seed": [1, 1], "tolerance": 1e400}]})");
  expect_one_line_error(run_cli(dir, {"segment", project.string(), "--script", script.string()}), 2,
                        "ops.json: line 1");
}

TEST(Refusals, ReplaysAreBoundedAndTheirIntegersNeverWrap) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  std::string waits = R"({"events": [)";
  for (int k = 0; k < 200; ++k) waits += std::string(k ? "," : "") + R"({"wait": 100000})";
  waits += "]}";
  for (const auto& [text, words] : std::vector<std::pair<std::string, std::string>>{
           {waits, "more than 1000000 events"},
           {R"({"events": [{"wait": 4294967297}]})", "wait must be a whole number from 0"},
           {R"({"events": [{"wait": 2.5}]})", "wait must be a whole number"},
           {R"({"events": [{"click": [10, 10], "buton": "left"}]})", "unknown key \"buton\""},
           {R"({"events": [{"click": {"pixel": [1, 2], "view3d": [0.5, 0.5]}}]})",
            "a place is [x, y], a widget's name"},
           {R"({"events": [{"click": {"view3d": [2, 0.5]}}]})", "x must be"},
           {R"({"events": [{"drag": ["commit", {"widget": ""}]}]})", "a widget is named"},
           {R"({"events": [{"layout": "step.txt"}]})", "layout names a .json file"},
           {R"({"events": [], "speed": 2})", "unknown key \"speed\""}}) {
    const std::filesystem::path replay = write_text(dir, "replay.json", text);
    // Refused before a window opens: no display is needed.
    const CliResult run =
        run_cli(dir, {"workbench", project.string(), "--replay", replay.string()}, "DISPLAY=");
    expect_one_line_error(run, 2, words);
    EXPECT_THAT(run.err, HasSubstr("replay.json")) << text;
  }
}

TEST(Refusals, NodeNamesHoldNoControlCharactersAndAreBounded) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  const std::string before = test::read_file_bytes(project);
  for (const std::string& name : {std::string("wall\\u001b[31m"), std::string("two\\nlines"),
                                  std::string("nul\\u0000"), std::string(300, 'x')}) {
    const std::filesystem::path script =
        write_text(dir, "ops.json", R"({"ops": [{"op": "group", "name": ")" + name + "\"}]}");
    const CliResult run = run_cli(dir, {"segment", project.string(), "--script", script.string()});
    expect_one_line_error(run, 2, "name");
  }
  EXPECT_EQ(test::read_file_bytes(project), before);
}

TEST(Refusals, AScriptThatCannotBeWrittenWholeStoresNothing) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  const std::string history = run_cli(dir, {"history", project.string(), "--json"}).out;
  std::string ops;
  for (int k = 0; k < 40; ++k) ops += std::string(k ? "," : "") + R"({"op": "group", "name": "g"})";
  const std::filesystem::path script = write_text(dir, "ops.json", R"({"ops": [)" + ops + "]}");
  // The write-ahead log may not grow past 8 KB: the batch's commit fails.
  const CliResult full =
      test::run_shell(dir, "trap '' XFSZ; ulimit -f 16; exec \"$SCANBENCH\" segment " +
                               test::shell_quote(project.string()) + " --script " +
                               test::shell_quote(script.string()));
  expect_one_line_error(full, 1, "p.sbproj");
  EXPECT_EQ(run_cli(dir, {"history", project.string(), "--json"}).out, history);
  EXPECT_EQ(run_cli(dir, {"check", project.string()}).exit_code, 0);
}

TEST(Refusals, ARefusedImportLeavesTheFileByteForByteAndIsBadInputEvenReadOnly) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const std::string before = test::read_file_bytes(project);
  // A good file first, then a bad one: the bad one is found before anything is written.
  const std::vector<std::string> bad = {fixture("good/ptx/two_scans.ptx").string(),
                                        fixture("bad/e57_bad_checksum.e57").string()};
  std::vector<std::string> args = {"import", project.string()};
  args.insert(args.end(), bad.begin(), bad.end());
  expect_one_line_error(run_cli(dir, args), 2, "e57_bad_checksum.e57");
  EXPECT_EQ(test::read_file_bytes(project), before);
  // Into a project another user cannot write: still bad input, exit 2.
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run commands as another user";
  const CliResult read_only = test::run_shell(
      dir, "exec setpriv --reuid=65534 --regid=65534 --clear-groups \"$SCANBENCH\" import " +
               test::shell_quote(project.string()) + " " +
               test::shell_quote(fixture("bad/e57_bad_checksum.e57").string()));
  expect_one_line_error(read_only, 2, "e57_bad_checksum.e57");
  EXPECT_EQ(test::read_file_bytes(project), before);
}

TEST(Refusals, EveryRefusalNamesTheFileAndKeepsItsMessageShort) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const CliResult recolor =
      run_cli(dir, {"recolor", project.string(), "--object", "no such wall", "--brightness", "5"});
  expect_one_line_error(recolor, 2, "p.sbproj");
  EXPECT_THAT(recolor.err, HasSubstr("no node is named \"no such wall\""));
  // A usage error's text is cut to 240 characters, as every part of a message.
  const CliResult usage = run_cli(dir, {"info", project.string(), "--" + std::string(5000, 'x')});
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_LT(usage.err.size(), 320u) << usage.err.size();
  const std::filesystem::path script =
      write_text(dir, "ops.json", R"({"ops": [{"op": "clear"}], "scann": 1})");
  expect_one_line_error(run_cli(dir, {"segment", project.string(), "--script", script.string()}), 2,
                        "unknown key \"scann\"");
}

// A choice that names no value lists the names, not CLI11's numbers.
TEST(Refusals, AChoiceThatNamesNoValueListsTheNames) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  make_project(dir, project);
  const CliResult format =
      run_cli(dir, {"export", project.string(), "--format", "xyz", "-o", (dir / "o").string()});
  expect_one_line_error(format, 2, "xyz is not one of csv, e57, las, ply, ptx, triplet");
  EXPECT_THAT(format.err, Not(HasSubstr("->")));
  expect_one_line_error(run_cli(dir, {"register", project.string(), "--coarse", "icp"}), 2,
                        "icp is not one of features, none, pairs, point_pairs");
  // Any case names a value.
  EXPECT_EQ(
      run_cli(dir, {"export", project.string(), "--format", "CSV", "-o", (dir / "o.csv").string()})
          .exit_code,
      0);
}

// A registration in which no pair of scans registers is a failure that
// names each pair and why, and stores nothing.
TEST(Refusals, ARegistrationWithNoPairRegisteredFailsAndStoresNothing) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  const std::string before = test::read_file_bytes(project);
  const CliResult registered = run_cli(dir, {"register", project.string()});
  EXPECT_EQ(registered.exit_code, 1) << registered.out;
  EXPECT_THAT(registered.err, HasSubstr("no pair of scans registered, nothing stored"));
  EXPECT_THAT(registered.err, HasSubstr("scan 2 to scan 1: "));
  EXPECT_THAT(run_cli(dir, {"history", project.string()}).out, Not(HasSubstr("register")));
}

// A scan that came without an E57 guid (PTX) gets the same one in every
// E57 export of the project, and each scan its own.
TEST(Refusals, AnE57ExportNamesAScanAlikeEveryTime) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  const auto guids_of_export = [&](const std::string& name) {
    const std::filesystem::path e57 = dir / (name + ".e57"), back = dir / (name + ".sbproj");
    EXPECT_EQ(
        run_cli(dir, {"export", project.string(), "--format", "e57", "-o", e57.string()}).exit_code,
        0);
    EXPECT_EQ(run_cli(dir, {"import", back.string(), e57.string()}).exit_code, 0);
    const nlohmann::json info =
        nlohmann::json::parse(run_cli(dir, {"info", back.string(), "--json"}).out);
    std::vector<std::string> guids;
    for (const auto& scan : info["scans"]) guids.push_back(scan["source"]["guid"]);
    return guids;
  };
  const std::vector<std::string> first = guids_of_export("a");
  ASSERT_EQ(first.size(), 2u);
  EXPECT_NE(first[0], first[1]);
  EXPECT_EQ(first[0].size(), 38u);  // {8-4-4-4-12}
  EXPECT_EQ(guids_of_export("b"), first);
}

}  // namespace
}  // namespace scanbench

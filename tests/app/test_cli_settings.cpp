// Replay through the journal: `history --settings ID` prints a command's
// settings, and `--settings FILE` runs the command with them again.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

using test::CliResult;
using test::run_cli;
using test::ScratchDir;
using ::testing::HasSubstr;

// A project of two simulated scans, off their true poses.
class CliSettings : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(run_cli(dir_, {"simulate", "--site", "campus", "--out", (dir_ / "sim").string(),
                             "--scans", "2", "--columns", "360", "--rows", "90", "--pose-error-deg",
                             "1", "--pose-error-m", "0.2"})
                  .exit_code,
              0);
    ok({"import", project_, (dir_ / "sim/campus_scan_01.json").string(),
        (dir_ / "sim/campus_scan_02.json").string()});
  }

  CliResult ok(const std::vector<std::string>& args) {
    const CliResult result = run_cli(dir_, args);
    EXPECT_EQ(result.exit_code, 0) << args[0] << ": " << result.err;
    return result;
  }

  // Command `id`'s settings, written to a file named `name`.
  std::string settings_file(std::int64_t id, const std::string& name) {
    const std::filesystem::path file = dir_ / name;
    std::ofstream(file) << ok({"history", project_, "--settings", std::to_string(id)}).out;
    return file.string();
  }

  nlohmann::json history() {
    return nlohmann::json::parse(ok({"history", project_, "--json"}).out)["commands"];
  }

  ScratchDir dir_;
  std::string project_ = (dir_ / "p.sbproj").string();
};

// Results without their timings, which differ from run to run.
nlohmann::json untimed(nlohmann::json result) {
  if (result.is_object()) {
    for (auto it = result.begin(); it != result.end();) {
      if (it.key() == "seconds" || it.key().ends_with("_seconds")) {
        it = result.erase(it);
      } else {
        ++it;
      }
    }
    for (auto& [key, value] : result.items()) value = untimed(value);
  } else if (result.is_array()) {
    for (auto& value : result) value = untimed(value);
  }
  return result;
}

TEST_F(CliSettings, EachBatchCommandRunsAgainWithTheSettingsHistoryPrints) {
  ok({"geometry", project_, "--window", "6", "--edge-window", "3", "--no-mixed-pixels"});
  ok({"register", project_, "--coarse", "none", "--no-global"});
  ok({"merge", project_});
  ok({"harmonize", project_, "--model", "matrix"});
  const std::string done = ok({"info", project_, "--json"}).out;
  const nlohmann::json first = history();
  ASSERT_EQ(first.size(), 5u);
  const std::vector<std::string> files{
      settings_file(2, "geometry.json"), settings_file(3, "register.json"),
      settings_file(4, "merge.json"), settings_file(5, "harmonize.json")};
  EXPECT_EQ(nlohmann::json::parse(test::read_file_bytes(files[0]))["window_radius"], 6);
  for (int k = 0; k < 4; ++k) ok({"undo", project_});

  ok({"geometry", project_, "--settings", files[0]});
  ok({"register", project_, "--settings", files[1], "--threads", "1"});
  ok({"merge", project_, "--settings", files[2]});
  ok({"harmonize", project_, "--settings", files[3]});
  // The new commands ended the redo chain: they replaced the undone ones.
  const nlohmann::json again = history();
  ASSERT_EQ(again.size(), 5u);
  for (std::size_t k = 1; k < 5; ++k) {
    const nlohmann::json& before = first[k];
    const nlohmann::json& after = again[k];
    EXPECT_EQ(after["name"], before["name"]);
    EXPECT_EQ(after["settings"], before["settings"]) << before["name"];
    EXPECT_EQ(untimed(after["result"]), untimed(before["result"])) << before["name"];
  }
  EXPECT_EQ(ok({"info", project_, "--json"}).out, done);
}

TEST_F(CliSettings, ABadSettingsFileIsBadInputNamingTheFileAndKeyAndChangesNothing) {
  const std::string before = test::read_file_bytes(project_);
  const auto refused = [&](const std::string& command, const std::string& json,
                           const std::string& what) {
    const std::filesystem::path file = dir_ / "bad.json";
    std::ofstream(file) << json;
    const CliResult result = run_cli(dir_, {command, project_, "--settings", file.string()});
    EXPECT_EQ(result.exit_code, 2) << json;
    EXPECT_THAT(result.err, HasSubstr(file.string())) << json;
    EXPECT_THAT(result.err, HasSubstr(what)) << json;
    EXPECT_EQ(test::read_file_bytes(project_), before) << json;
  };
  refused("geometry", R"({"window_radius": 2.7})", "key \"window_radius\"");
  refused("geometry", R"({"windw_radius": 3})", "unknown key");
  refused("geometry", R"({"threads": 3})", "--threads");
  refused("geometry", R"({"edge_window_radius": 40})", "key \"edge_window_radius\"");
  refused("geometry", "{\n  \"window_radius\": 1e400\n}", "line 2");
  refused("register", R"({"registration": {"icp": {"max_iterations": 4294967297}}})",
          "key \"registration.icp.max_iterations\"");
  refused("merge", R"({"noise": {"noise_m": -0.1}})", "key \"noise.noise_m\"");
  refused("harmonize", R"({"model": "curves"})", "curves");

  // The options the file replaces cannot be given with it.
  const std::filesystem::path empty = dir_ / "empty.json";
  std::ofstream(empty) << "{}";
  for (const std::vector<std::string>& mixed :
       {std::vector<std::string>{"geometry", project_, "--settings", empty.string(), "--window",
                                 "4"},
        {"register", project_, "--settings", empty.string(), "--coarse", "none"},
        {"harmonize", project_, "--settings", empty.string(), "--model", "matrix"}}) {
    const CliResult result = run_cli(dir_, mixed);
    EXPECT_EQ(result.exit_code, 2) << mixed[0];
    EXPECT_THAT(result.err, HasSubstr("excludes")) << mixed[0];
  }
  EXPECT_EQ(test::read_file_bytes(project_), before);

  const CliResult missing = run_cli(dir_, {"history", project_, "--settings", "99"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("has no command 99"));
}

}  // namespace
}  // namespace scanbench

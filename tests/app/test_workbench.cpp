// The workbench driven by recorded input under Xvfb, through the window's
// input path: a new user's session on the simulated campus. Keller Hall is
// segmented into its two walls seen from scan 1 (seed clicks in the
// panoramic view, names typed, Enter to commit), the walls are grouped, one
// is recoloured with the colour editor's slider, Ctrl+Z takes the recolour
// back, and the 3D view is flown through. Each stage is a replay of its own
// process; the widgets' places come from the layout the previous stage
// wrote. SCANBENCH_SCREENSHOTS (a folder) keeps the screenshots for the
// user guide.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench::test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

// The workbench under a virtual X server of its own.
CliResult run_on_display(const ScratchDir& dir, const std::vector<std::string>& args) {
  std::vector<std::string> all = {"workbench"};
  all.insert(all.end(), args.begin(), args.end());
  return run_cli(dir, all, "xvfb-run -a -s '-screen 0 1280x800x24'");
}

json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// The campus's first scan at a quarter of the resolution (0.4° steps) with
// its geometry: Keller Hall's west wall faces the scanner at column 654, row
// 116, its south wall at column 617, row 82.
std::filesystem::path campus_project(const ScratchDir& dir) {
  const std::filesystem::path project = dir / "campus.sbproj";
  const std::vector<std::vector<std::string>> steps = {
      {"simulate", "--site", "campus", "--scans", "1", "--columns", "900", "--rows", "225", "--out",
       (dir / "sim").string()},
      {"import", project.string(), (dir / "sim" / "campus_scan_01.json").string()},
      {"geometry", project.string()}};
  for (const std::vector<std::string>& step : steps) {
    const CliResult result = run_cli(dir, step);
    EXPECT_EQ(result.exit_code, 0) << step.front() << ": " << result.err;
  }
  return project;
}

// A replay's events file.
std::filesystem::path events(const ScratchDir& dir, const std::string& name, const json& list) {
  const std::filesystem::path file = dir / name;
  std::ofstream(file) << json{{"events", list}}.dump(1);
  return file;
}

struct Layout {
  json data;
  json widget(const std::string& name) const {
    EXPECT_TRUE(data["widgets"].contains(name)) << name;
    return data["widgets"][name];
  }
  // The window position of a scan pixel's centre in the panoramic view.
  json pixel(int col, int row) const {
    const json& p = data["panorama"];
    const double scale = p["scale"].get<double>();
    return {p["x"].get<double>() + (col + 0.5) * scale, p["y"].get<double>() + (row + 0.5) * scale};
  }
  json view3d_centre() const {
    const json& v = data["view3d"];
    return {v[0].get<double>() + 0.5 * v[2].get<double>(),
            v[1].get<double>() + 0.5 * v[3].get<double>()};
  }
};

json nodes(const ScratchDir& dir, const std::filesystem::path& project) {
  return json::parse(run_cli(dir, {"objects", project.string(), "--json"}).out)["nodes"];
}

void keep_screenshot(const std::filesystem::path& file) {
  const char* folder = std::getenv("SCANBENCH_SCREENSHOTS");
  if (folder == nullptr || !std::filesystem::exists(file)) return;
  std::filesystem::copy_file(file, std::filesystem::path(folder) / file.filename(),
                             std::filesystem::copy_options::overwrite_existing);
}

TEST(Workbench, ANewUserSegmentsGroupsRecoloursUndoesAndFlies) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const auto run = [&](const std::string& stage, const json& list) {
    const std::filesystem::path layout = dir / ("layout_" + stage + ".json");
    const std::filesystem::path shot = dir / ("workbench_" + stage + ".png");
    const CliResult result = run_on_display(
        dir, {project.string(), "--replay", events(dir, stage + ".json", list).string(),
              "--screenshot", shot.string(), "--layout", layout.string()});
    EXPECT_EQ(result.exit_code, 0) << stage << ": " << result.err;
    EXPECT_TRUE(std::filesystem::exists(shot)) << stage;
    keep_screenshot(shot);
    return Layout{read_json(layout)};
  };

  // Opening the project: the panels and views laid out.
  const Layout start = run("open", json::array());
  EXPECT_EQ(start.data["panorama"]["columns"], 900);

  // Two walls: a seed click each, named in the name field, Enter commits.
  const Layout segmented = run("segment", {{{"click", start.pixel(654, 116)}},
                                           {{"wait", 2}},
                                           {{"click", start.widget("name")}},
                                           {{"key", "A"}, {"mods", {"ctrl"}}},
                                           {{"text", "wall west"}},
                                           {{"key", "Enter"}},
                                           {{"click", start.pixel(617, 82)}},
                                           {{"wait", 2}},
                                           {{"click", start.widget("name")}},
                                           {{"text", "wall south"}},
                                           {{"key", "Enter"}}});
  json tree = nodes(dir, project);
  ASSERT_EQ(tree.size(), 2u);
  EXPECT_EQ(tree[0]["name"], "wall west");
  EXPECT_EQ(tree[1]["name"], "wall south");
  EXPECT_GT(tree[0]["points"].get<int>(), 1500);
  EXPECT_GT(tree[1]["points"].get<int>(), 1500);

  // Grouped: click one wall, Ctrl+click the other, name the group, Group.
  const Layout grouped =
      run("group", {{{"click", segmented.widget("node wall west")}},
                    {{"click", segmented.widget("node wall south")}, {"mods", {"ctrl"}}},
                    {{"click", segmented.widget("name")}},
                    {{"text", "keller hall"}},
                    {{"click", segmented.widget("group")}},
                    {{"wait", 2}}});
  tree = nodes(dir, project);
  ASSERT_EQ(tree.size(), 3u);
  EXPECT_EQ(tree[2]["name"], "keller hall");
  EXPECT_EQ(tree[2]["kind"], "group");
  EXPECT_EQ(tree[0]["parent"], tree[2]["id"]);
  EXPECT_EQ(tree[1]["parent"], tree[2]["id"]);

  // The west wall recoloured: its hue slider clicked three quarters along
  // and its saturation raised, Apply; the screenshot shows it; then Ctrl+Z.
  json hue = grouped.widget("hue");
  hue[0] = hue[0].get<double>() + 55.0;
  json saturation = grouped.widget("saturation");
  saturation[0] = saturation[0].get<double>() + 80.0;
  run("recolor", {{{"click", grouped.widget("node wall west")}},
                  {{"click", hue}},
                  {{"click", saturation}},
                  {{"click", grouped.widget("apply colour")}},
                  {{"wait", 2}},
                  {{"screenshot", "workbench_recolored.png"}}});
  keep_screenshot(dir / "workbench_recolored.png");
  tree = nodes(dir, project);
  ASSERT_TRUE(tree[0].contains("color"));
  EXPECT_GT(tree[0]["color"]["hue_deg"].get<double>(), 30.0);
  EXPECT_GT(tree[0]["color"]["saturation"].get<double>(), 1.5);

  // Undo, then fly: V, forward for a second, a look to the side.
  const json centre = grouped.view3d_centre();
  run("fly", {{{"key", "Z"}, {"mods", {"ctrl"}}},
              {{"move", centre}},
              {{"key", "V"}},
              {{"hold", "W"}, {"frames", 30}},
              {{"drag", {centre, {centre[0].get<double>() + 120.0, centre[1]}}}, {"steps", 8}}});
  tree = nodes(dir, project);
  EXPECT_FALSE(tree[0].contains("color"));
  const json history =
      json::parse(run_cli(dir, {"history", project.string(), "--json"}).out)["commands"];
  ASSERT_FALSE(history.empty());
  EXPECT_EQ(history.back()["name"], "recolor");
  EXPECT_EQ(history.back()["state"], "undone");

  // Drag and drop in the object tree: the south wall out of the group to
  // the roots (the panel's empty part), then back onto the group.
  json empty = grouped.widget("node wall south");
  empty[1] = empty[1].get<double>() + 100.0;
  const Layout out =
      run("reparent_out", {{{"drag", {grouped.widget("node wall south"), empty}}}, {{"wait", 2}}});
  tree = nodes(dir, project);
  EXPECT_TRUE(tree[1]["parent"].is_null());
  run("reparent_in",
      {{{"drag", {out.widget("node wall south"), out.widget("node keller hall")}}}, {{"wait", 2}}});
  tree = nodes(dir, project);
  EXPECT_EQ(tree[1]["parent"], tree[2]["id"]);
}

// Clicking another scan in the Scans panel opens it: the panel's list,
// which opening a scan reloads, was walked while it was replaced
// (std::bad_alloc or SIGSEGV, 5 times in 5).
TEST(Workbench, ClickingAnotherScanOpensIt) {
  const ScratchDir dir;
  const std::filesystem::path project = dir / "two.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  const std::filesystem::path layout = dir / "layout.json";
  ASSERT_EQ(run_on_display(dir, {project.string(), "--replay",
                                 events(dir, "look.json", {{{"wait", 1}}}).string(), "--layout",
                                 layout.string()})
                .exit_code,
            0);
  const json click = Layout{read_json(layout)}.widget("scan 2");
  const CliResult run = run_on_display(dir, {project.string(), "--replay",
                                             events(dir, "open.json",
                                                    {{{"screenshot", "a.png"}},
                                                     {{"click", click}},
                                                     {{"wait", 3}},
                                                     {{"screenshot", "b.png"}}})
                                                 .string(),
                                             "--layout", layout.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "b.png"));
  EXPECT_EQ(read_json(layout)["scan"], 2);
}

TEST(Workbench, BadEventsAndProjectsAreRefusedByName) {
  const ScratchDir dir;
  const std::filesystem::path project = dir / "empty.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  const std::filesystem::path bad =
      events(dir, "bad.json", {{{"click", {10, 20}}}, {{"key", "NoSuchKey"}}});
  const CliResult refused = run_on_display(dir, {project.string(), "--replay", bad.string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("bad.json"));
  EXPECT_THAT(refused.err, HasSubstr("events[1]"));
  EXPECT_THAT(refused.err, HasSubstr("NoSuchKey"));
  const std::filesystem::path not_json = dir / "not.json";
  std::ofstream(not_json) << "{\"events\": [";
  EXPECT_EQ(run_on_display(dir, {project.string(), "--replay", not_json.string()}).exit_code, 2);
  // Without a display at all: a runtime failure that says what to do.
  const CliResult no_display = run_cli(dir, {"workbench", project.string(), "--replay",
                                             events(dir, "ok.json", json::array()).string()});
  if (std::getenv("DISPLAY") == nullptr) {
    EXPECT_EQ(no_display.exit_code, 1);
    EXPECT_THAT(no_display.err, HasSubstr("xvfb-run"));
  }
}

}  // namespace
}  // namespace scanbench::test

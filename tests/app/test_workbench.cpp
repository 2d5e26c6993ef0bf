// The workbench driven by recorded input under Xvfb, through the window's
// input path: a new user's session on the simulated campus. Keller Hall is
// segmented into its two walls seen from scan 1 (seed clicks in the
// panoramic view, names typed, Enter to commit), the walls are grouped, one
// is recoloured with the colour editor's slider, Ctrl+Z takes the recolour
// back, and the 3D view is flown through. A replay names the widgets it
// clicks and the scan pixels it seeds from; the workbench finds them in the
// frame each event is fed to, so one process plays a whole session, and a
// test checks the project between processes. SCANBENCH_SCREENSHOTS (a
// folder) keeps the screenshots for the user guide.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "acquisition/formats/image_decoder.hpp"
#include "cli_runner.hpp"
#include "modeling/lod/lod_store.hpp"
#include "support/test_support.hpp"

namespace scanbench::test {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

// The workbench under a virtual X server of its own. Under the sanitizers
// its leak check is off: LeakSanitizer's tracer, stopping the world at exit
// while Mesa's llvmpipe threads wind down, crashed once in about 40 runs
// ("Tracer caught signal 11"); address and undefined-behaviour checks stay.
CliResult run_on_display(const ScratchDir& dir, const std::vector<std::string>& args,
                         const std::string& screen = "1280x800") {
  std::vector<std::string> all = {"workbench"};
  all.insert(all.end(), args.begin(), args.end());
  const char* asan = std::getenv("ASAN_OPTIONS");
  const std::string no_leak_check =
      asan == nullptr ? "" : "env ASAN_OPTIONS='" + std::string(asan) + ":detect_leaks=0' ";
  return run_cli(dir, all, no_leak_check + "xvfb-run -a -s '-screen 0 " + screen + "x24'");
}

json read_json(const std::filesystem::path& file) {
  std::ifstream in(file);
  return json::parse(in);
}

// The campus's first scan at a quarter of the resolution (0.4° steps) with
// its geometry: Keller Hall's west wall faces the scanner at column 654, row
// 116, its south wall at column 617, row 82. Simulated, imported and
// measured once per test process; each test gets a copy of the project and
// the simulator's output (sim/) in its own folder.
std::filesystem::path campus_project(const ScratchDir& dir) {
  static const ScratchDir built;
  static const bool made = [] {
    const std::filesystem::path project = built / "campus.sbproj";
    const std::vector<std::vector<std::string>> steps = {
        {"simulate", "--site", "campus", "--scans", "1", "--columns", "900", "--rows", "225",
         "--out", (built / "sim").string()},
        {"import", project.string(), (built / "sim" / "campus_scan_01.json").string()},
        {"geometry", project.string()}};
    for (const std::vector<std::string>& step : steps) {
      const CliResult result = run_cli(built, step);
      EXPECT_EQ(result.exit_code, 0) << step.front() << ": " << result.err;
      if (result.exit_code != 0) return false;
    }
    return true;
  }();
  if (made) {
    std::filesystem::copy(built.path(), dir.path(), std::filesystem::copy_options::recursive);
  } else {
    ADD_FAILURE() << "the campus project could not be made";
  }
  return dir / "campus.sbproj";
}

// A replay's events file.
std::filesystem::path events(const ScratchDir& dir, const std::string& name, const json& list) {
  const std::filesystem::path file = dir / name;
  std::ofstream(file) << json{{"events", list}}.dump(1);
  return file;
}

// Places a replay names (app/workbench/replay.hpp), found when the event is
// fed: a widget by its name is the string itself.
json pixel(int col, int row) {
  return {{"pixel", {col, row}}};
}
json widget(const std::string& name, double dx, double dy) {
  return {{"widget", name}, {"offset", {dx, dy}}};
}
json view3d(double fx, double fy, double dx = 0.0, double dy = 0.0) {
  return {{"view3d", {fx, fy}}, {"offset", {dx, dy}}};
}

// The events that grow a region from a seed click at scan pixel (col, row)
// and commit it under `name`, typed over the name field's text.
json commit_events(int col, int row, const std::string& name) {
  return {{{"click", pixel(col, row)}},       {{"wait", 2}},    {{"click", "name"}},
          {{"key", "A"}, {"mods", {"ctrl"}}}, {{"text", name}}, {{"key", "Enter"}}};
}

// The event lists `parts` one after the other.
json concat(std::initializer_list<json> parts) {
  json out = json::array();
  for (const json& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

// A layout the workbench wrote (--layout, or a replay's "layout" event):
// the widgets drawn in that frame, the views, the scan shown, the selection.
struct Layout {
  json data;
  json widget(const std::string& name) const {
    EXPECT_TRUE(data["widgets"].contains(name)) << name;
    return data["widgets"][name];
  }
  bool draws(const std::string& name) const { return data["widgets"].contains(name); }
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

// Replays `list` on `project` as stage `stage`: its screenshot
// (workbench_STAGE.png, kept for the user guide) and the layout it leaves.
Layout run_stage(const ScratchDir& dir, const std::filesystem::path& project,
                 const std::string& stage, const json& list) {
  const std::filesystem::path layout = dir / ("layout_" + stage + ".json");
  const std::filesystem::path shot = dir / ("workbench_" + stage + ".png");
  const CliResult result = run_on_display(
      dir, {project.string(), "--replay", events(dir, stage + ".json", list).string(),
            "--screenshot", shot.string(), "--layout", layout.string()});
  EXPECT_EQ(result.exit_code, 0) << stage << ": " << result.err;
  EXPECT_TRUE(std::filesystem::exists(shot)) << stage;
  keep_screenshot(shot);
  return Layout{read_json(layout)};
}

// The commands of the project's journal, oldest first: name, state,
// settings and result.
json commands(const ScratchDir& dir, const std::filesystem::path& project) {
  return json::parse(run_cli(dir, {"history", project.string(), "--json"}).out)["commands"];
}

// The level-of-detail store beside `project` holds what `scanbench lod
// --rebuild` of a copy of the project gives, node for node.
void expect_store_as_built(const ScratchDir& dir, const std::filesystem::path& project) {
  const std::filesystem::path copy = dir / "rebuilt" / project.filename();
  std::filesystem::create_directories(copy.parent_path());
  std::filesystem::copy_file(project, copy, std::filesystem::copy_options::overwrite_existing);
  ASSERT_EQ(run_cli(dir, {"lod", copy.string(), "--rebuild"}).exit_code, 0);
  const lod::LodStore updated = lod::LodStore::open(lod::LodStore::path_for(project));
  const lod::LodStore built = lod::LodStore::open(lod::LodStore::path_for(copy));
  EXPECT_EQ(updated.header().project_revision, built.header().project_revision);
  EXPECT_EQ(updated.header().points, built.header().points);
  const std::vector<lod::LodNodeInfo> nodes = updated.nodes();
  const std::vector<lod::LodNodeInfo> expected = built.nodes();
  ASSERT_EQ(nodes.size(), expected.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    ASSERT_EQ(nodes[k].key.code(), expected[k].key.code());
    EXPECT_EQ(nodes[k].level_ends, expected[k].level_ends);
    EXPECT_TRUE(updated.read_points(nodes[k].key) == built.read_points(expected[k].key))
        << "node " << nodes[k].key.code();
  }
}

TEST(Workbench, ANewUserSegmentsGroupsRecoloursUndoesAndFlies) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  // Opening the project, then two walls: a seed click each, named in the
  // name field, Enter commits. Grouped: click one wall, Ctrl+click the
  // other, name the group, Group. The west wall recoloured: its hue slider
  // clicked three quarters along and its saturation raised, Apply. Then
  // Ctrl+Z takes the recolour back, and V flies: forward, a look aside.
  const json session =
      concat({{{{"screenshot", "workbench_open.png"}}, {{"layout", "layout_open.json"}}},
              commit_events(654, 116, "wall west"),
              commit_events(617, 82, "wall south"),
              {{{"wait", 2}},
               {{"screenshot", "workbench_segment.png"}},
               {{"layout", "layout_segment.json"}},
               {{"click", "node wall west"}},
               {{"click", "node wall south"}, {"mods", {"ctrl"}}},
               {{"click", "name"}},
               {{"text", "keller hall"}},
               {{"click", "group"}},
               {{"wait", 2}},
               {{"screenshot", "workbench_group.png"}},
               {{"click", "node wall west"}},
               {{"click", widget("hue", 55.0, 0.0)}},
               {{"click", widget("saturation", 80.0, 0.0)}},
               {{"click", "apply colour"}},
               {{"wait", 2}},
               {{"screenshot", "workbench_recolored.png"}},
               {{"key", "Z"}, {"mods", {"ctrl"}}},
               {{"move", view3d(0.5, 0.5)}},
               {{"key", "V"}},
               {{"hold", "W"}, {"frames", 12}},
               {{"drag", {view3d(0.5, 0.5), view3d(0.5, 0.5, 120.0, 0.0)}}, {"steps", 4}},
               {{"layout", "layout_flown.json"}}}});
  run_stage(dir, project, "fly", session);
  // The 3D view's store: built once when the project opened without one,
  // then updated in place by each commit, not built again.
  EXPECT_EQ(read_json(dir / "layout_flown.json")["store"]["builds"], 1);
  EXPECT_GE(read_json(dir / "layout_flown.json")["store"]["updates"].get<int>(), 2);
  // The flight's moving frames kept to their point budget; their times
  // against the target are reported, not asserted (a loaded machine).
  const json flown_frames = read_json(dir / "layout_flown.json")["frames"];
  EXPECT_GE(flown_frames["moving"].get<int>(), 5) << flown_frames.dump();
  EXPECT_EQ(flown_frames["over_budget"], 0) << flown_frames.dump();
  std::cout << "moving frames: " << flown_frames.dump() << "\n";
  for (const char* shot : {"workbench_open.png", "workbench_segment.png", "workbench_group.png",
                           "workbench_recolored.png"})
    keep_screenshot(dir / shot);
  EXPECT_EQ(read_json(dir / "layout_open.json")["panorama"]["columns"], 900);
  const Layout segmented{read_json(dir / "layout_segment.json")};
  EXPECT_TRUE(segmented.draws("node wall west") && segmented.draws("node wall south"));
  EXPECT_FALSE(segmented.draws("node keller hall"));

  json tree = nodes(dir, project);
  ASSERT_EQ(tree.size(), 3u);
  EXPECT_EQ(tree[0]["name"], "wall west");
  EXPECT_EQ(tree[1]["name"], "wall south");
  EXPECT_GT(tree[0]["points"].get<int>(), 1500);
  EXPECT_GT(tree[1]["points"].get<int>(), 1500);
  EXPECT_EQ(tree[2]["name"], "keller hall");
  EXPECT_EQ(tree[2]["kind"], "group");
  EXPECT_EQ(tree[0]["parent"], tree[2]["id"]);
  EXPECT_EQ(tree[1]["parent"], tree[2]["id"]);
  EXPECT_FALSE(tree[0].contains("color"));  // undone
  // The recolour, kept in the journal as undone (redo would bring it back).
  json history = commands(dir, project);
  std::vector<std::string> names;
  for (const json& c : history) names.push_back(c["name"].get<std::string>());
  EXPECT_EQ(names, (std::vector<std::string>{"import", "geometry", "commit", "commit", "group",
                                             "recolor"}));
  ASSERT_FALSE(history.empty());
  json& recolor = history.back();
  EXPECT_EQ(recolor["state"], "undone");
  EXPECT_EQ(recolor["result"]["node"], tree[0]["id"]);
  EXPECT_GT(recolor["result"]["color"]["hue_deg"].get<double>(), 30.0) << recolor.dump();
  EXPECT_GT(recolor["result"]["color"]["saturation"].get<double>(), 1.5) << recolor.dump();

  // Drag and drop in the object tree: the south wall out of the group to
  // the roots (the panel's empty part), then back onto the group. Deleting
  // the group asks first: cancelled, nothing changes (the group is still
  // drawn); confirmed, the group goes with its walls.
  const json ask = {{{"click", "node keller hall"}}, {{"click", "delete"}}, {{"wait", 2}}};
  json arrange = {
      {{"drag", {"node wall south", widget("node wall south", 0.0, 100.0)}}},
      {{"wait", 2}},
      {{"layout", "layout_reparent_out.json"}},
      {{"drag", {"node wall south", "node keller hall"}}},
      {{"wait", 2}},
  };
  arrange.insert(arrange.end(), ask.begin(), ask.end());
  arrange.push_back({{"screenshot", "workbench_delete_asked.png"}});
  arrange.push_back({{"click", "question no"}});
  arrange.push_back({{"wait", 2}});
  arrange.push_back({{"layout", "layout_delete_cancelled.json"}});
  arrange.insert(arrange.end(), ask.begin(), ask.end());
  arrange.push_back({{"click", "question yes"}});
  arrange.push_back({{"wait", 2}});
  arrange.push_back({{"layout", "layout_arranged.json"}});
  run_stage(dir, project, "arrange", arrange);
  // Opened with a current store; the delete updated it in place, and it
  // holds what a build from scratch of the project gives, node for node.
  EXPECT_EQ(read_json(dir / "layout_arranged.json")["store"]["builds"], 0);
  EXPECT_GE(read_json(dir / "layout_arranged.json")["store"]["updates"].get<int>(), 1);
  expect_store_as_built(dir, project);
  EXPECT_TRUE(Layout{read_json(dir / "layout_reparent_out.json")}.draws("node wall south"));
  const Layout cancelled{read_json(dir / "layout_delete_cancelled.json")};
  EXPECT_TRUE(cancelled.draws("node keller hall") && cancelled.draws("node wall west"));
  EXPECT_FALSE(cancelled.draws("question yes"));
  EXPECT_TRUE(nodes(dir, project).empty());
  // The journal: the recolour's redo branch ended by the first move, the
  // south wall moved to the roots and back, one delete.
  json after = commands(dir, project);
  ASSERT_EQ(after.size(), 8u) << after.dump();
  EXPECT_EQ(after[5]["name"], "edit");
  EXPECT_TRUE(after[5]["settings"].contains("parent") && after[5]["settings"]["parent"].is_null())
      << after[5].dump();
  EXPECT_EQ(after[6]["name"], "edit");
  EXPECT_EQ(after[6]["settings"]["parent"], tree[2]["id"]) << after[6].dump();
  EXPECT_EQ(after[7]["name"], "delete");

  // A box drawn in the 3D view with the lasso tool (Shift held) selects the
  // points in front inside it, still to be segmented; Enter in the name
  // field commits them as an object, which is then hidden; Ctrl+Z twice
  // shows it again and takes it back, giving the selection back. The
  // store follows the commit and its undo in place; the hide rewrites
  // nothing.
  const json lasso = {
      {{"wait", 2}},
      {{"key", "L"}},
      {{"drag", {view3d(0.35, 0.35), view3d(0.65, 0.65)}}, {"mods", {"shift"}}, {"steps", 6}},
      {{"wait", 1}},
      {{"screenshot", "workbench_lasso_drawn.png"}},
      {{"layout", "layout_lasso.json"}},
      {{"click", "name"}},
      {{"key", "A"}, {"mods", {"ctrl"}}},
      {{"text", "lassoed"}},
      {{"key", "Enter"}},
      {{"wait", 2}},
      {{"layout", "layout_lasso_committed.json"}},
      {{"click", "node lassoed"}},
      {{"click", "hide"}},
      {{"wait", 2}},
      {{"layout", "layout_lasso_hidden.json"}},
      {{"key", "Z"}, {"mods", {"ctrl"}}},
      {{"wait", 2}},
      {{"key", "Z"}, {"mods", {"ctrl"}}},
      {{"wait", 2}},
      {{"layout", "layout_lasso_undone.json"}}};
  run_stage(dir, project, "lasso3d", lasso);
  keep_screenshot(dir / "workbench_lasso_drawn.png");
  const json selected = read_json(dir / "layout_lasso.json")["selection"];
  EXPECT_GT(selected["pixels"].get<int>(), 1000) << read_json(dir / "layout_lasso.json")["status"];
  EXPECT_EQ(selected["scans"], 1);
  const json committed = read_json(dir / "layout_lasso_committed.json");
  EXPECT_EQ(committed["selection"]["pixels"], 0);
  const json hidden = read_json(dir / "layout_lasso_hidden.json");
  EXPECT_EQ(hidden["store"], committed["store"]);
  const json undone = read_json(dir / "layout_lasso_undone.json");
  EXPECT_EQ(undone["selection"]["pixels"], selected["pixels"]);
  EXPECT_EQ(undone["store"]["builds"], 0);
  EXPECT_GE(undone["store"]["updates"].get<int>(), 2);
  // One renderer, which followed the commit and the undo keeping the nodes
  // they did not rewrite.
  EXPECT_EQ(undone["renderer"]["opened"], 1);
  EXPECT_GE(undone["renderer"]["follows"].get<int>(), 2);
  json lassoed = commands(dir, project);
  ASSERT_EQ(lassoed.size(), 10u) << lassoed.dump();
  EXPECT_EQ(lassoed[8]["name"], "commit");
  EXPECT_EQ(lassoed[8]["state"], "undone");
  EXPECT_EQ(lassoed[8]["result"]["points"], selected["pixels"]);
  EXPECT_EQ(lassoed[9]["name"], "edit");
  EXPECT_EQ(lassoed[9]["settings"]["hidden"], true) << lassoed[9].dump();
  EXPECT_EQ(lassoed[9]["state"], "undone");
  EXPECT_TRUE(nodes(dir, project).empty());
  expect_store_as_built(dir, project);
}

// Whether a screenshot's pixel (B, G, R) is the 3D view's background.
bool background(const cv::Vec3b& p) {
  return std::abs(p[0] - 36) <= 3 && std::abs(p[1] - 31) <= 3 && std::abs(p[2] - 28) <= 3;
}

// The share of the pixels of a window region (x, y, w, h) that the second
// screenshot shows darker than the first, by more than 30 of 255 in every
// channel, of those that are not the 3D view's background in both.
double darkened_share(const std::filesystem::path& before, const std::filesystem::path& after,
                      int x0, int y0, int w, int h) {
  const acquisition::DecodedImage a = acquisition::decode_image(before, 800, 1280);
  const acquisition::DecodedImage b = acquisition::decode_image(after, 800, 1280);
  EXPECT_TRUE(a.problem.empty() && b.problem.empty()) << a.problem << b.problem;
  if (!a.problem.empty() || !b.problem.empty()) return 0.0;
  std::size_t drawn = 0, darker = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      const cv::Vec3b& p = a.pixels.at<cv::Vec3b>(y, x);
      const cv::Vec3b& q = b.pixels.at<cv::Vec3b>(y, x);
      if (background(p) && background(q)) continue;
      ++drawn;
      darker += p[0] > q[0] + 30 && p[1] > q[1] + 30 && p[2] > q[2] + 30;
    }
  }
  return drawn == 0 ? 0.0 : static_cast<double>(darker) / static_cast<double>(drawn);
}

// The share of a window region's pixels the 3D view drew (not its
// background).
double drawn_share(const std::filesystem::path& picture, int x0, int y0, int w, int h) {
  const acquisition::DecodedImage a = acquisition::decode_image(picture, 800, 1280);
  EXPECT_TRUE(a.problem.empty()) << a.problem;
  if (!a.problem.empty()) return 0.0;
  std::size_t drawn = 0;
  for (int y = y0; y < y0 + h; ++y) {
    for (int x = x0; x < x0 + w; ++x) {
      drawn += !background(a.pixels.at<cv::Vec3b>(y, x));
    }
  }
  return static_cast<double>(drawn) / static_cast<double>(w * h);
}

// A wall segmented in scan 1 of a two-scan campus takes its points in scan
// 2 too (the merge keeps many of scan 2's), so recolouring it recolours the
// wall the 3D view shows, not only scan 1's share of it.
TEST(Workbench, ARecolouredWallChangesColourInEveryScanOfTheModel) {
  const ScratchDir dir;
  const std::filesystem::path project = dir / "campus2.sbproj";
  const std::vector<std::vector<std::string>> steps = {
      {"simulate", "--site", "campus", "--scans", "2", "--columns", "900", "--rows", "225", "--out",
       (dir / "sim").string()},
      {"import", project.string(), (dir / "sim" / "campus_scan_01.json").string(),
       (dir / "sim" / "campus_scan_02.json").string()},
      {"geometry", project.string()},
      {"merge", project.string()}};
  for (const std::vector<std::string>& step : steps) {
    const CliResult result = run_cli(dir, step);
    ASSERT_EQ(result.exit_code, 0) << step.front() << ": " << result.err;
  }
  // The west wall committed from scan 1; Frame; its brightness near its
  // lowest (−50), clicked at the slider's left end, Apply; then the
  // clipping box around it.
  const json frame_wall = {
      {{"click", "node wall west"}}, {{"wait", 1}}, {{"key", "F"}}, {{"wait", 3}}};
  json session = concat(
      {commit_events(654, 116, "wall west"), {{{"wait", 2}}, {{"layout", "layout_carry.json"}}}});
  session.insert(session.end(), frame_wall.begin(), frame_wall.end());
  for (const json& e : json::array({{{"screenshot", "workbench_carry_before.png"}},
                                    {{"click", widget("brightness", -105.0, 0.0)}},
                                    {{"click", "apply colour"}},
                                    {{"wait", 3}},
                                    {{"screenshot", "workbench_carry_after.png"}}}))
    session.push_back(e);
  session.insert(session.end(), frame_wall.begin(), frame_wall.end());
  session.push_back({{"click", "clip to selection"}});
  session.push_back({{"wait", 3}});
  session.push_back({{"screenshot", "workbench_clip.png"}});
  run_stage(dir, project, "carry", session);
  for (const char* shot :
       {"workbench_carry_before.png", "workbench_carry_after.png", "workbench_clip.png"})
    keep_screenshot(dir / shot);
  const json tree = nodes(dir, project);
  ASSERT_EQ(tree.size(), 1u);
  json history = commands(dir, project);
  ASSERT_EQ(history.size(), 5u) << history.dump();  // import, geometry, merge, commit, recolor
  json& result = history[3]["result"];
  EXPECT_GT(result["other_scans_points"].get<int>(), result["points"].get<int>() / 2);
  EXPECT_EQ(history[4]["name"], "recolor");
  // Frame puts the wall at the 3D view's centre, filling its middle: there
  // nearly every pixel darkens (had the object only scan 1's points, the
  // merge's share of scan 2 would stay as it was). The view's left edge
  // shows another building, which keeps its colour.
  const json v = read_json(dir / "layout_carry.json")["view3d"];
  const int x = v[0].get<int>(), y = v[1].get<int>(), w = v[2].get<int>(), h = v[3].get<int>();
  const std::filesystem::path before = dir / "workbench_carry_before.png";
  const std::filesystem::path after = dir / "workbench_carry_after.png";
  EXPECT_GT(
      darkened_share(before, after, x + w * 43 / 100, y + h * 35 / 100, w * 14 / 100, h * 30 / 100),
      0.8);
  EXPECT_LT(darkened_share(before, after, x, y + h / 4, w / 10, h / 2), 0.05);

  // The clipping box around the wall leaves the other building out.
  const std::filesystem::path clip = dir / "workbench_clip.png";
  EXPECT_GT(drawn_share(after, x, y + h / 4, w / 10, h / 2), 0.5);
  EXPECT_LT(drawn_share(clip, x, y + h / 4, w / 10, h / 2), 0.02);
  EXPECT_GT(drawn_share(clip, x + w * 43 / 100, y + h * 35 / 100, w * 14 / 100, h * 30 / 100), 0.9);
}

// The states of the journal's commands, oldest first.
std::vector<std::string> journal(const ScratchDir& dir, const std::filesystem::path& project) {
  std::vector<std::string> out;
  for (const json& c : commands(dir, project))
    out.push_back(c["name"].get<std::string>() + " " + c["state"].get<std::string>());
  return out;
}

// Ctrl+Z takes back the workbench's own edits, then stops before a batch
// stage and asks; cancelled, nothing changes; confirmed, the stage is undone
// and the workbench stays open without geometry, and then without scans.
TEST(Workbench, CtrlZStopsBeforeABatchStageAndAsks) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const json undo = {{"key", "Z"}, {"mods", {"ctrl"}}};
  // The click grows a selection (session state: no command), the first
  // Ctrl+Z takes it back, and the second asks: No, then again and Yes.
  // Had No undone the geometry, Yes would have undone the import.
  run_stage(dir, project, "undo_geometry",
            {{{"click", pixel(654, 116)}},
             {{"wait", 2}},
             undo,
             undo,
             {{"wait", 2}},
             {{"screenshot", "workbench_undo_question.png"}},
             {{"layout", "layout_asked.json"}},
             {{"click", "question no"}},
             {{"wait", 1}},
             {{"layout", "layout_cancelled.json"}},
             undo,
             {{"wait", 2}},
             {{"click", "question yes"}},
             {{"wait", 2}}});
  keep_screenshot(dir / "workbench_undo_question.png");
  EXPECT_TRUE(Layout{read_json(dir / "layout_asked.json")}.draws("question yes"));
  EXPECT_FALSE(Layout{read_json(dir / "layout_cancelled.json")}.draws("question yes"));
  EXPECT_EQ(journal(dir, project), (std::vector<std::string>{"import done", "geometry undone"}));
  // With the import undone too the project has no scans; it still opens,
  // and Ctrl+Y there brings the import back.
  ASSERT_EQ(run_cli(dir, {"undo", project.string()}).exit_code, 0);
  run_stage(dir, project, "redo_import",
            {{{"screenshot", "workbench_no_scans.png"}},
             {{"key", "Y"}, {"mods", {"ctrl"}}},
             {{"wait", 2}}});
  keep_screenshot(dir / "workbench_no_scans.png");
  EXPECT_EQ(journal(dir, project).front(), "import done");
}

// Automatic proposals open as a list to review: one accepted under a name,
// one rejected (its points back to the pool), two merged.
TEST(Workbench, ProposalsAreReviewedOneByOne) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  run_stage(dir, project, "proposals_reviewed",
            {{{"click", "propose"}},
             {{"wait", 3}},
             {{"screenshot", "workbench_proposals.png"}},
             {{"click", "proposal proposal 1"}},
             {{"wait", 2}},
             {{"click", "name"}},
             {{"key", "A"}, {"mods", {"ctrl"}}},
             {{"text", "north hall"}},
             {{"click", "accept proposal"}},
             {{"wait", 2}},
             {{"layout", "layout_accepted.json"}},
             {{"click", "proposal proposal 2"}},
             {{"wait", 2}},
             {{"click", "reject proposal"}},
             {{"wait", 2}},
             {{"layout", "layout_rejected.json"}},
             {{"click", "proposal proposal 3"}},
             {{"wait", 1}},
             {{"click", "proposal proposal 4"}, {"mods", {"ctrl"}}},
             {{"wait", 1}},
             {{"click", "merge proposals"}},
             {{"wait", 2}}});
  keep_screenshot(dir / "workbench_proposals.png");
  // The group and its proposals, less the one rejected and one of the two
  // merged; the accepted one at the roots under its name.
  json history = commands(dir, project);
  ASSERT_GE(history.size(), 3u);
  ASSERT_EQ(history[2]["name"], "propose") << history.dump();
  const std::size_t made = 1 + history[2]["result"]["proposals"].get<std::size_t>();
  ASSERT_GE(made, 5u);
  const json tree = nodes(dir, project);
  EXPECT_EQ(tree.size(), made - 2);
  const auto accepted_node = std::find_if(tree.begin(), tree.end(),
                                          [](const json& n) { return n["name"] == "north hall"; });
  ASSERT_NE(accepted_node, tree.end());
  EXPECT_TRUE((*accepted_node)["parent"].is_null());
  const Layout accepted{read_json(dir / "layout_accepted.json")};
  EXPECT_TRUE(accepted.draws("node north hall") && accepted.draws("proposal proposal 2"));
  EXPECT_FALSE(Layout{read_json(dir / "layout_rejected.json")}.draws("proposal proposal 2"));
}

// The events that tick "measure" and click places `a` then `b`.
json measure_events(const json& a, const json& b) {
  return {{{"click", "measure"}}, {{"wait", 1}},  {{"click", a}},
          {{"wait", 2}},          {{"click", b}}, {{"wait", 2}}};
}

// The points of the distance the journal's newest "measure" command saved
// (none, with a failure, when it saved no distance).
json measured_distance(const ScratchDir& dir, const std::filesystem::path& project) {
  json history = commands(dir, project);
  for (auto c = history.rbegin(); c != history.rend(); ++c) {
    if ((*c)["name"] != "measure") continue;
    json& list = (*c)["result"]["measurements"];
    if (list.size() != 1 || list[0]["kind"] != "distance") break;
    return list[0]["points"];
  }
  ADD_FAILURE() << "no distance saved: " << history.dump();
  return json::array();
}

// Measuring: with "measure" on, two clicks in the 3D view pick two points
// of the model and save a distance; the project keeps it (a "measure"
// command), and Export CSV writes it.
TEST(Workbench, TwoClicksInThe3dViewMeasureADistance) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  // Export CSV writes to the file the field names (by default beside the
  // project), replacing an earlier one only once confirmed: declined first.
  std::filesystem::path written = project;
  written.replace_extension();
  written += "_measurements.csv";
  std::ofstream(written) << "an earlier export\n";
  const auto text_of = [](const std::filesystem::path& file) {
    std::ifstream in(file);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  json declined = measure_events(view3d(0.5, 0.5), view3d(0.5, 0.5, 80.0, 40.0));
  for (const json& e : json::array({{{"screenshot", "workbench_measure.png"}},
                                    {{"click", "export csv"}},
                                    {{"wait", 1}},
                                    {{"layout", "layout_csv_asked.json"}},
                                    {{"click", "question no"}},
                                    {{"wait", 1}}}))
    declined.push_back(e);
  run_stage(dir, project, "measure_csv_declined", declined);
  keep_screenshot(dir / "workbench_measure.png");
  EXPECT_TRUE(Layout{read_json(dir / "layout_csv_asked.json")}.draws("question yes"));
  EXPECT_EQ(text_of(written), "an earlier export\n");
  const json points = measured_distance(dir, project);
  ASSERT_EQ(points.size(), 2u);
  double squared = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double d = points[1][a].get<double>() - points[0][a].get<double>();
    squared += d * d;
  }
  EXPECT_GT(std::sqrt(squared), 0.5);  // two points of the campus, apart
  run_stage(dir, project, "measure_csv",
            {{{"click", "export csv"}}, {{"wait", 1}}, {{"click", "question yes"}}, {{"wait", 1}}});
  EXPECT_THAT(text_of(written), HasSubstr("\"distance 1\",distance,"));
  // The command line lists them and writes the CSV too, never over the project.
  const json listed_json =
      json::parse(run_cli(dir, {"measurements", project.string(), "--json"}).out);
  ASSERT_EQ(listed_json["measurements"].size(), 1u);
  EXPECT_NEAR(listed_json["measurements"][0]["value"].get<double>(), std::sqrt(squared), 1e-9);
  EXPECT_EQ(
      run_cli(dir, {"measurements", project.string(), "--csv", (dir / "m.csv").string()}).exit_code,
      0);
  EXPECT_TRUE(std::filesystem::exists(dir / "m.csv"));
  const CliResult over_project =
      run_cli(dir, {"measurements", project.string(), "--csv", project.string(), "--force"});
  EXPECT_NE(over_project.exit_code, 0);
}

// Measuring in the panoramic view: two clicks on Keller Hall's west and
// south walls make a distance between the scan's own samples at those
// pixels. Each lies as far from the scanner as the simulator's true range
// there, within 4 σ of the range noise.
TEST(Workbench, ClicksInThePanoramaMeasureTheScansSamples) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const std::vector<std::array<int, 2>> pixels = {{654, 116}, {617, 82}};  // column, row
  run_stage(dir, project, "measure_panorama",
            measure_events(pixel(pixels[0][0], pixels[0][1]), pixel(pixels[1][0], pixels[1][1])));
  const json points = measured_distance(dir, project);
  ASSERT_EQ(points.size(), 2u);
  const json truth = read_json(dir / "sim" / "truth.json");
  const json& pose = truth["scans"][0]["T_world_scan"];  // row-major 4 × 4
  const Eigen::Vector3d scanner(pose[3].get<double>(), pose[7].get<double>(),
                                pose[11].get<double>());
  const acquisition::DecodedImage range =
      acquisition::decode_image(dir / "sim" / "truth" / "campus_scan_01_range.tiff", 225, 900);
  ASSERT_TRUE(range.problem.empty()) << range.problem;
  for (std::size_t k = 0; k < 2; ++k) {
    const json& p = points[k];
    const Eigen::Vector3d point(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    const double true_range = range.pixels.at<float>(pixels[k][1], pixels[k][0]);
    const double sigma = 0.005 + 5e-5 * true_range;
    EXPECT_NEAR((point - scanner).norm(), true_range, 4.0 * sigma) << "point " << k;
  }
}

// Pixels of scan 1 around (col, row) on the same simulated surface, away
// from its edges (the truth's object ids agree over 5 × 5 pixels, none
// mixed), at least 4 pixels apart: picks that surely hit a sample.
std::vector<json> surface_pixels(const ScratchDir& dir, int col, int row, std::size_t count) {
  const auto truth = [&](const char* name) {
    return acquisition::decode_image(dir / "sim" / "truth" / name, 225, 900).pixels;
  };
  const cv::Mat ids = truth("campus_scan_01_object_id.png");
  const cv::Mat mixed = truth("campus_scan_01_mixed.png");
  const auto id_at = [&](int r, int c) {
    return ids.depth() == CV_16U ? ids.at<std::uint16_t>(r, c) : ids.at<std::uint8_t>(r, c);
  };
  const auto mixed_at = [&](int r, int c) {
    return mixed.depth() == CV_16U ? mixed.at<std::uint16_t>(r, c) != 0
                                   : mixed.at<std::uint8_t>(r, c) != 0;
  };
  const int object = id_at(row, col);
  std::vector<std::array<int, 2>> found;
  for (int radius = 0; radius < 30 && found.size() < count; ++radius) {
    for (int r = row - radius; r <= row + radius; ++r) {
      for (int c = col - radius; c <= col + radius; ++c) {
        if (std::max(std::abs(r - row), std::abs(c - col)) != radius || found.size() >= count)
          continue;
        if (r < 2 || c < 2 || r >= 223 || c >= 898) continue;
        bool inside = true;
        for (int dr = -2; dr <= 2 && inside; ++dr)
          for (int dc = -2; dc <= 2 && inside; ++dc)
            inside = id_at(r + dr, c + dc) == object && !mixed_at(r + dr, c + dc);
        bool apart = true;
        for (const auto& f : found)
          apart = apart && std::max(std::abs(f[0] - c), std::abs(f[1] - r)) >= 4;
        if (inside && apart) found.push_back({c, r});
      }
    }
  }
  EXPECT_EQ(found.size(), count) << "surface pixels near " << col << ", " << row;
  std::vector<json> out;
  for (const auto& [c, r] : found) out.push_back(pixel(c, r));
  return out;
}

// Every kind of measurement, taken in the panoramic view on Keller Hall's
// west wall: the kind chosen from its list, its points clicked (an area
// finished with Enter), each saved as it is complete.
TEST(Workbench, EveryKindOfMeasurementIsTaken) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const std::vector<json> at = surface_pixels(dir, 654, 116, 3);
  ASSERT_EQ(at.size(), 3u);
  json list = {{{"click", "measure"}}, {{"wait", 1}}};
  const auto choose = [&](const std::string& kind, std::size_t points) {
    list.push_back({{"click", "measure kind"}});
    list.push_back({{"wait", 1}});
    list.push_back({{"click", "measure kind " + kind}});
    list.push_back({{"wait", 1}});
    for (std::size_t k = 0; k < points; ++k) {
      list.push_back({{"click", at[k]}});
      list.push_back({{"wait", 2}});
    }
  };
  choose("point", 1);
  choose("height", 2);
  choose("angle", 3);
  choose("area", 3);
  list.push_back({{"key", "Enter"}});
  list.push_back({{"wait", 2}});
  run_stage(dir, project, "measure_kinds", list);
  const json measured =
      json::parse(run_cli(dir, {"measurements", project.string(), "--json"}).out)["measurements"];
  ASSERT_EQ(measured.size(), 4u) << measured.dump();
  const std::vector<std::string> kinds = {"point", "height", "angle", "area"};
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    EXPECT_EQ(measured[k]["kind"], kinds[k]);
    EXPECT_TRUE(std::isfinite(measured[k]["value"].get<double>()));
  }
  EXPECT_EQ(measured[3]["points"].size(), 3u);
  const double angle = measured[2]["value"].get<double>();
  EXPECT_GT(angle, 0.0);
  EXPECT_LT(angle, 180.0);
  EXPECT_GT(measured[3]["value"].get<double>(), 0.0);  // three points of a wall span an area
}

// A click in the 3D view selects the object drawn there: the west wall is
// committed and framed, then the south wall committed (and selected); a
// click at the view's centre, on the west wall, selects it instead.
TEST(Workbench, AClickInThe3dViewSelectsTheObjectDrawnThere) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const Layout done = run_stage(dir, project, "select3d",
                                {{{"click", pixel(654, 116)}},
                                 {{"wait", 2}},
                                 {{"key", "C"}},
                                 {{"wait", 2}},
                                 {{"key", "F"}},
                                 {{"wait", 2}},
                                 {{"click", pixel(617, 82)}},
                                 {{"wait", 2}},
                                 {{"key", "C"}},
                                 {{"wait", 2}},
                                 {{"click", view3d(0.5, 0.5)}},
                                 {{"wait", 2}}});
  const json list = nodes(dir, project);
  ASSERT_EQ(list.size(), 2u);
  const std::int64_t west = list[0]["id"].get<std::int64_t>();
  EXPECT_EQ(done.data["selected"], json::array({west}));
}

// A session recorded with --record and replayed on a copy of the project
// as it was leaves the same journal: every command, its settings and state.
TEST(Workbench, ARecordedSessionReplaysToTheSameJournal) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const std::filesystem::path copy = dir / "copy.sbproj";
  std::filesystem::copy_file(project, copy);
  // The recording holds the window points the named places were found at.
  const json session = concat({commit_events(654, 116, "wall west"),
                               {{{"wait", 2}},
                                {{"click", pixel(617, 82)}},
                                {{"wait", 2}},
                                {{"key", "C"}},
                                {{"wait", 2}},
                                {{"key", "Z"}, {"mods", {"ctrl"}}},
                                {{"wait", 2}}}});
  const std::filesystem::path record = dir / "recorded.json";
  const CliResult recorded = run_on_display(
      dir, {project.string(), "--replay", events(dir, "session.json", session).string(), "--record",
            record.string()});
  ASSERT_EQ(recorded.exit_code, 0) << recorded.err;
  ASSERT_TRUE(std::filesystem::exists(record));
  const CliResult replayed = run_on_display(dir, {copy.string(), "--replay", record.string()});
  ASSERT_EQ(replayed.exit_code, 0) << replayed.err;
  const auto summary = [&](const std::filesystem::path& file) {
    json out = json::array();
    for (const json& c : commands(dir, file))
      out.push_back({c["name"], c["state"], c["settings"], c["result"]});
    return out;
  };
  const json original = summary(project);
  // import, geometry, commit, commit (undone): the undo gave the second
  // commit's selection back, and closing did not keep it, which would have
  // ended the redo chain.
  ASSERT_EQ(original.size(), 4u);
  EXPECT_EQ(original[3][0], "commit");
  EXPECT_EQ(original[3][1], "undone");
  EXPECT_EQ(summary(copy), original);
  // An existing file is never replaced by a recording.
  const CliResult again = run_on_display(dir, {project.string(), "--record", record.string()});
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_THAT(again.err, HasSubstr("exists"));
}

// Read-only, by flag or because nobody may write the file (root included):
// a click grows a selection (session state) and Ctrl+Z takes it back, a
// commit is refused, and the journal stays as it was.
TEST(Workbench, ReadOnlyWritesNothing) {
  const ScratchDir dir;
  const std::filesystem::path project = campus_project(dir);
  const json edits = {
      {{"click", pixel(654, 116)}},       {{"wait", 2}}, {{"key", "C"}}, {{"wait", 1}},
      {{"key", "Z"}, {"mods", {"ctrl"}}}, {{"wait", 1}}};
  const std::vector<std::string> before = journal(dir, project);
  const std::filesystem::path shot = dir / "workbench_read_only.png";
  const CliResult flagged = run_on_display(
      dir, {project.string(), "--read-only", "--replay", events(dir, "edits.json", edits).string(),
            "--screenshot", shot.string()});
  EXPECT_EQ(flagged.exit_code, 0) << flagged.err;
  keep_screenshot(shot);
  EXPECT_EQ(journal(dir, project), before);
  std::filesystem::permissions(project, std::filesystem::perms::owner_read |
                                            std::filesystem::perms::group_read |
                                            std::filesystem::perms::others_read);
  const CliResult protected_file = run_on_display(
      dir, {project.string(), "--replay", events(dir, "edits2.json", edits).string()});
  EXPECT_EQ(protected_file.exit_code, 0) << protected_file.err;
  std::filesystem::permissions(project, std::filesystem::perms::owner_write,
                               std::filesystem::perm_options::add);
  EXPECT_EQ(journal(dir, project), before);
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
  const CliResult run = run_on_display(dir, {project.string(), "--replay",
                                             events(dir, "open.json",
                                                    {{{"screenshot", "a.png"}},
                                                     {{"click", "scan 2"}},
                                                     {{"wait", 3}},
                                                     {{"screenshot", "b.png"}}})
                                                 .string(),
                                             "--layout", layout.string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "b.png"));
  EXPECT_EQ(read_json(layout)["scan"], 2);
}

// An unstructured cloud has no range image: the panoramic view says so
// instead of showing its points in file order, and a click there grows
// nothing, while the 3D view draws the cloud.
TEST(Workbench, AnUnstructuredCloudSaysItHasNoRangeImage) {
  const ScratchDir dir;
  const std::filesystem::path project = dir / "cloud.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string(),
                          fixture("good/ply/unorganized_binary.ply").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  // A click where scan 1's pixel (0, 0) was in the panoramic view (the
  // cloud has no pixels for a named place to find: window pixels, from the
  // layout scan 1 opens with).
  const std::filesystem::path layout = dir / "layout.json";
  ASSERT_EQ(run_on_display(dir, {project.string(), "--replay",
                                 events(dir, "look.json", {{{"wait", 1}}}).string(), "--layout",
                                 layout.string()})
                .exit_code,
            0);
  const json p = read_json(layout)["panorama"];
  const double half = 0.5 * p["scale"].get<double>();
  const json corner = {p["x"].get<double>() + half, p["y"].get<double>() + half};
  const CliResult run = run_on_display(
      dir, {project.string(), "--replay",
            events(dir, "cloud.json",
                   {{{"click", "scan 2"}}, {{"wait", 2}}, {{"click", corner}}, {{"wait", 1}}})
                .string(),
            "--layout", layout.string(), "--screenshot", (dir / "workbench_cloud.png").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  keep_screenshot(dir / "workbench_cloud.png");
  const json after = read_json(layout);
  EXPECT_EQ(after["scan"], 2);
  EXPECT_THAT(after["status"].get<std::string>(),
              HasSubstr("refused: this scan is an unstructured cloud"));
}

// On a screen twice as large each way, the panels, fonts and widgets are
// twice as large (not a 1280 × 800 corner of it), and clicks at the larger
// window's places act as at the smaller's.
TEST(Workbench, PanelsScaleWithTheWindow) {
  const ScratchDir dir;
  const std::filesystem::path project = dir / "two.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  const auto layout_at = [&](int width, const json& list) {
    const std::filesystem::path layout = dir / ("layout_" + std::to_string(width) + ".json");
    const std::filesystem::path shot = dir / ("workbench_scaled_" + std::to_string(width) + ".png");
    const std::string screen = std::to_string(width) + "x" + std::to_string(width * 5 / 8);
    const CliResult run =
        run_on_display(dir,
                       {project.string(), "--size", std::to_string(width), "--replay",
                        events(dir, "look.json", list).string(), "--layout", layout.string(),
                        "--screenshot", shot.string()},
                       screen);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    keep_screenshot(shot);
    return Layout{read_json(layout)};
  };
  // On the large screen, a click on "scan 2" (found where the large window
  // draws it) then opens it.
  const Layout small = layout_at(1280, {{{"wait", 1}}});
  const Layout opened = layout_at(
      2560,
      {{{"wait", 1}}, {{"layout", "layout_2560_open.json"}}, {{"click", "scan 2"}}, {{"wait", 2}}});
  EXPECT_EQ(opened.data["scan"], 2);
  const Layout large{read_json(dir / "layout_2560_open.json")};
  EXPECT_EQ(small.data["ui_scale"], 1.0);
  EXPECT_EQ(large.data["ui_scale"], 2.0);
  EXPECT_NEAR(large.data["panorama"]["x"].get<double>(),
              2.0 * small.data["panorama"]["x"].get<double>(), 1.0);
  EXPECT_NEAR(large.data["view3d"][3].get<double>(), 2.0 * small.data["view3d"][3].get<double>(),
              2.0);
  for (const std::string widget : {"scan 2", "commit", "undo", "apply colour"}) {
    for (int axis = 0; axis < 2; ++axis) {
      EXPECT_NEAR(large.widget(widget)[axis].get<double>(),
                  2.0 * small.widget(widget)[axis].get<double>(), 6.0)
          << widget << " axis " << axis;
    }
  }
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
  // A widget the frame does not draw: refused when the event is fed, by
  // its place in the file and its name.
  const std::filesystem::path missing =
      events(dir, "missing.json", {{{"wait", 1}}, {{"click", "no such widget"}}});
  const CliResult not_drawn = run_on_display(dir, {project.string(), "--replay", missing.string()});
  EXPECT_EQ(not_drawn.exit_code, 2);
  EXPECT_THAT(not_drawn.err, HasSubstr("missing.json"));
  EXPECT_THAT(not_drawn.err, HasSubstr("events[1]"));
  EXPECT_THAT(not_drawn.err, HasSubstr("\"no such widget\" is not drawn"));
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

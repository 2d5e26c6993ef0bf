// End-to-end tests of the scanbench executable: exit codes, JSON output, and
// that refused input leaves a project untouched.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "acquisition/formats/las_reader.hpp"
#include "acquisition/formats/ply_reader.hpp"
#include "app/cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

using test::fixture;
using test::ScratchDir;

using test::CliResult;
using test::run_cli;
using ::testing::HasSubstr;

nlohmann::json info_json(const ScratchDir& dir, const std::filesystem::path& path) {
  const CliResult info = run_cli(dir, {"info", path.string(), "--json"});
  EXPECT_EQ(info.exit_code, 0) << info.err;
  return nlohmann::json::parse(info.out);
}

// The one scan a reader makes of a cloud narrow enough for one.
acquisition::ImportedScan only(std::vector<acquisition::ImportedScan> scans) {
  EXPECT_EQ(scans.size(), 1u);
  return std::move(scans.at(0));
}

// Runs a call that must succeed.
CliResult expect_ok(const ScratchDir& dir, const std::vector<std::string>& args) {
  CliResult result = run_cli(dir, args);
  EXPECT_EQ(result.exit_code, 0) << args[0] << ": " << result.err;
  return result;
}

TEST(Cli, HelpSucceedsForEverySubcommand) {
  ScratchDir dir;
  for (const char* command :
       {"import", "info", "export", "bench", "simulate", "geometry", "register", "merge", "history",
        "undo", "redo", "check", "objects", "segment", "render", "recolor", "harmonize"}) {
    const CliResult help = run_cli(dir, {command, "--help"});
    EXPECT_EQ(help.exit_code, 0) << command;
    EXPECT_NE(help.out.find("Usage"), std::string::npos) << command;
  }
}

TEST(Cli, UsageErrorsExitWithTwo) {
  ScratchDir dir;
  EXPECT_EQ(run_cli(dir, {}).exit_code, 2);
  EXPECT_EQ(run_cli(dir, {"frobnicate"}).exit_code, 2);
  EXPECT_EQ(run_cli(dir, {"export", "x.sbproj", "--format", "obj", "-o", "y"}).exit_code, 2);
}

TEST(Cli, ObjectsPrintsTheTreeAsATableOrJson) {
  ScratchDir dir;
  // Version 5's fixture holds the group "north hall" with "wall south" in it.
  const std::filesystem::path project = dir / "objects.sbproj";
  std::filesystem::copy_file(fixture("projects/version5.sbproj"), project);
  const CliResult json = run_cli(dir, {"objects", project.string(), "--json"});
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const nlohmann::json nodes = nlohmann::json::parse(json.out)["nodes"];
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[0]["name"], "north hall");
  EXPECT_EQ(nodes[0]["kind"], "group");
  EXPECT_TRUE(nodes[0]["parent"].is_null());
  EXPECT_TRUE(nodes[0]["bbox_world"].is_null());
  EXPECT_EQ(nodes[1]["parent"], 1);
  EXPECT_EQ(nodes[1]["points"], 5);
  EXPECT_EQ(nodes[1]["bbox_world"],
            nlohmann::json::parse("[[-1.0, 0.5, -0.25], [1.5, 2.0, 0.75]]"));
  const CliResult table = run_cli(dir, {"objects", project.string()});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("  north hall\n"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("    wall south\n"), std::string::npos) << table.out;  // indented
  // A project without objects says so; a file that is not a project is bad input.
  ASSERT_EQ(run_cli(dir, {"import", (dir / "bare.sbproj").string(),
                          fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  EXPECT_NE(run_cli(dir, {"objects", (dir / "bare.sbproj").string()}).out.find("no objects"),
            std::string::npos);
  EXPECT_EQ(run_cli(dir, {"objects", fixture("good/ptx/tiny_color.ptx").string()}).exit_code, 2);
}

// A project of two_scans.ptx with its geometry, and a script file.
std::filesystem::path segmentable_project(const ScratchDir& dir) {
  const std::filesystem::path project = dir / "segment.sbproj";
  EXPECT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  EXPECT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  return project;
}

std::filesystem::path write_script(const ScratchDir& dir, const std::string& name,
                                   const std::string& text) {
  const std::filesystem::path file = dir / name;
  std::ofstream(file) << text;
  return file;
}

TEST(Cli, SegmentScriptBuildsTheTreeAndEachOpIsUndoable) {
  ScratchDir dir;
  const std::filesystem::path project = segmentable_project(dir);
  const std::filesystem::path script = write_script(dir, "ops.json", R"json({"scan": 1, "ops": [
    {"op": "group", "name": "site"},
    {"op": "lasso", "points": [[-0.5, -0.5], [3.5, -0.5], [3.5, 2.5], [-0.5, 2.5]]},
    {"op": "seed", "at": [0, 0]},
    {"op": "grow", "channel": "range", "tolerance": 50},
    {"op": "commit", "name": "wall", "parent": "site"},
    {"op": "rename", "node": "wall", "name": "wall south"}]})json");
  const CliResult run =
      run_cli(dir, {"segment", project.string(), "--script", script.string(), "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json ops = nlohmann::json::parse(run.out)["ops"];
  ASSERT_EQ(ops.size(), 6u);
  EXPECT_TRUE(ops[1]["command"].is_null());  // a lasso or a seed is the tool's state, not a change
  EXPECT_TRUE(ops[2]["command"].is_null());
  EXPECT_EQ(ops[3]["result"]["selected_pixels"], 12);
  const auto nodes = [&] {
    return nlohmann::json::parse(
        run_cli(dir, {"objects", project.string(), "--json"}).out)["nodes"];
  };
  ASSERT_EQ(nodes().size(), 2u);
  EXPECT_EQ(nodes()[1]["name"], "wall south");
  EXPECT_EQ(nodes()[1]["points"], 12);
  EXPECT_EQ(nodes()[0]["points"], 12);  // the group sums its objects
  // Each op is a command of its own, undone from other processes.
  ASSERT_EQ(run_cli(dir, {"undo", project.string()}).exit_code, 0);
  EXPECT_EQ(nodes()[1]["name"], "wall");
  ASSERT_EQ(run_cli(dir, {"undo", project.string()}).exit_code, 0);
  EXPECT_EQ(nodes().size(), 1u);
  // Redone, grouped into a building under the site, and ungrouped again.
  const std::filesystem::path more = write_script(dir, "more.json", R"json({"scan": 1, "ops": [
    {"op": "redo"}, {"op": "redo"},
    {"op": "group", "name": "building", "parent": "site", "children": ["wall south"]},
    {"op": "ungroup", "node": "building"},
    {"op": "lasso", "scan": 2, "points": [[-0.5, -0.5], [3.5, -0.5], [3.5, 2.5], [-0.5, 2.5]]},
    {"op": "grow", "scan": 2, "seed": [0, 0], "channel": "range", "tolerance": 50},
    {"op": "commit", "scan": 2, "name": "wall from scan 2", "parent": "site"},
    {"op": "merge", "nodes": ["wall south", "wall from scan 2"]}]})json");
  ASSERT_EQ(run_cli(dir, {"segment", project.string(), "--script", more.string()}).exit_code, 0);
  ASSERT_EQ(nodes().size(), 2u);  // the wall of scan 2 merged into scan 1's
  EXPECT_EQ(nodes()[1]["name"], "wall south");
  EXPECT_EQ(nodes()[1]["parent"], nodes()[0]["id"]);
  EXPECT_GT(nodes()[1]["points"].get<int>(), 12);
}

TEST(Cli, RecolorEditsAnObjectUndoablyAndRefusesWhatItCannotDo) {
  ScratchDir dir;
  const std::filesystem::path project = segmentable_project(dir);
  const std::filesystem::path script = write_script(dir, "ops.json", R"json({"scan": 1, "ops": [
    {"op": "group", "name": "site"},
    {"op": "grow", "seed": [0, 0], "channel": "range", "tolerance": 50},
    {"op": "commit", "name": "wall", "parent": "site"}]})json");
  ASSERT_EQ(run_cli(dir, {"segment", project.string(), "--script", script.string()}).exit_code, 0);
  const CliResult edited = run_cli(dir, {"recolor", project.string(), "--object", "wall",
                                         "--brightness", "12.5", "--hue", "30", "--json"});
  ASSERT_EQ(edited.exit_code, 0) << edited.err;
  const nlohmann::json color = nlohmann::json::parse(edited.out)["color"];
  EXPECT_EQ(color["brightness"], 12.5);
  EXPECT_EQ(color["hue_deg"], 30.0);
  const auto history_size = [&] {
    return nlohmann::json::parse(
               run_cli(dir, {"history", project.string(), "--json"}).out)["commands"]
        .size();
  };
  const std::size_t commands = history_size();
  // No such node, a value out of range, an edit mixed with a clone, a
  // clone without a source, a scan without colour: exit 2, nothing written.
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--object", "99", "--brightness", "1"},
        {"--object", "no such wall", "--brightness", "1"},
        {"--object", "2", "--contrast", "-1"},
        {"--object", "2", "--brightness", "1", "--clone", "1"},
        {"--to", "2"},
        {"--to", "2", "--paint-color", "#12345"},
        {"--to", "2", "--clone-region", "1:0:0:2:2"},
        {"--to", "2", "--clone-region", "1:4294967296:0:4294967306:10"},
        {"--to", "2", "--clone-region", "1:0:0:2"},
        {"--to", "2", "--clone-region", "1:0:0:2:2:"}}) {
    std::vector<std::string> args = {"recolor", project.string()};
    args.insert(args.end(), bad.begin(), bad.end());
    const CliResult refused = run_cli(dir, args);
    EXPECT_EQ(refused.exit_code, 2) << bad.front() << " " << bad.back();
    EXPECT_FALSE(refused.err.empty());
  }
  EXPECT_EQ(history_size(), commands);
  const CliResult harmonize = run_cli(dir, {"harmonize", project.string()});
  EXPECT_EQ(harmonize.exit_code, 2);  // the fixture's scans have no colour
  EXPECT_THAT(harmonize.err, HasSubstr("colour overlap"));
  ASSERT_EQ(run_cli(dir, {"undo", project.string()}).exit_code, 0);
  const nlohmann::json nodes =
      nlohmann::json::parse(run_cli(dir, {"objects", project.string(), "--json"}).out)["nodes"];
  EXPECT_FALSE(nodes[1].contains("color"));
  ASSERT_EQ(run_cli(dir, {"redo", project.string()}).exit_code, 0);
  EXPECT_THAT(run_cli(dir, {"objects", project.string()}).out, HasSubstr("wall (recoloured)"));
}

TEST(Cli, RenderDrawsTheProjectHeadlessAndRefusesBadViewsAndOutputs) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "render.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  const std::filesystem::path view =
      write_script(dir, "view.json",
                   R"json({"width": 64, "height": 48, "vertical_fov_deg": 60,
              "position": [0, 0, 0], "look_at": [1, 0, 0]})json");
  const std::filesystem::path picture = dir / "picture.png";
  const CliResult run = run_cli(
      dir, {"render", project.string(), "--view", view.string(), "-o", picture.string(), "--json"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out);
  EXPECT_EQ(out["width"], 64);
  EXPECT_EQ(out["mode"], "blended");
  for (const char* key :
       {"points", "points_submitted", "culled_frustum", "culled_budget", "nodes_drawn", "frame_ms"})
    EXPECT_TRUE(out.contains(key)) << key;
  EXPECT_GT(out["points_submitted"], 0);
  EXPECT_GT(std::filesystem::file_size(picture), 0u);
  // The level-of-detail store was built beside the project, and is used as
  // it is while the project does not change.
  EXPECT_GT(out["store_build_seconds"], 0.0);
  const CliResult again = run_cli(dir, {"render", project.string(), "--view", view.string(), "-o",
                                        picture.string(), "--force", "--json"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["store_build_seconds"], 0.0);
  // A fly-through: every frame drawn as the camera moves, the last one
  // refined until complete.
  const std::filesystem::path path = write_script(dir, "path.json",
                                                  R"json({"width": 64, "height": 48,
              "vertical_fov_deg": 60, "frames": [
                {"position": [0, 0, 0], "look_at": [1, 0, 0]},
                {"position": [0, 0, 0], "look_at": [1, 0.2, 0]},
                {"position": [0, 0, 0], "look_at": [1, 0.4, 0]}]})json");
  const CliResult flown = run_cli(dir, {"render", project.string(), "--path", path.string(), "-o",
                                        (dir / "last.png").string(), "--json"});
  ASSERT_EQ(flown.exit_code, 0) << flown.err;
  const nlohmann::json fly = nlohmann::json::parse(flown.out);
  EXPECT_EQ(fly["frames"], 3);
  for (const char* key : {"frame_ms_p50", "frame_ms_p95", "points_per_frame_p50",
                          "converge_seconds", "gpu_cache_bytes_peak", "first_frame_ms"})
    EXPECT_TRUE(fly.contains(key)) << key;
  EXPECT_TRUE(std::filesystem::exists(dir / "last.png"));
  EXPECT_EQ(run_cli(dir, {"render", project.string(), "--path", path.string(), "--view",
                          view.string(), "-o", (dir / "both.png").string()})
                .exit_code,
            2);
  EXPECT_EQ(run_cli(dir, {"render", project.string(), "-o", (dir / "none.png").string()}).exit_code,
            2);
  // Scans in frames hundreds of kilometres apart (one not registered yet)
  // cannot share a store: refused, naming the scan.
  const std::filesystem::path apart = segmentable_project(dir);
  const CliResult far = run_cli(
      dir, {"render", apart.string(), "--view", view.string(), "-o", (dir / "far.png").string()});
  EXPECT_EQ(far.exit_code, 2);
  EXPECT_THAT(far.err, HasSubstr("scan 2 (two_scans-2)"));
  EXPECT_FALSE(std::filesystem::exists(dir / "far.png"));
  // A view file without its camera, and a picture over the project: exit 2, nothing written.
  const std::filesystem::path bad = write_script(dir, "bad.json", R"json({"width": 64})json");
  const CliResult refused = run_cli(
      dir, {"render", project.string(), "--view", bad.string(), "-o", (dir / "x.png").string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr("bad.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
  const std::filesystem::path sneaky = dir / "segment.png";
  std::filesystem::create_symlink(project, sneaky);
  EXPECT_EQ(
      run_cli(dir, {"render", project.string(), "--view", view.string(), "-o", sneaky.string()})
          .exit_code,
      2);
  EXPECT_EQ(std::filesystem::read_symlink(sneaky), project);
}

TEST(Cli, ARefusedSegmentScriptLeavesTheTreeAsItWas) {
  ScratchDir dir;
  const std::filesystem::path project = segmentable_project(dir);
  const std::string before = run_cli(dir, {"objects", project.string(), "--json"}).out;
  // Refused while it runs: its first two ops are taken back.
  const std::filesystem::path late = write_script(dir, "late.json", R"json({"ops": [
    {"op": "group", "name": "site"},
    {"op": "grow", "seed": [0, 0], "channel": "range", "tolerance": 50},
    {"op": "commit", "name": "wall", "parent": "no such group"}]})json");
  const CliResult refused = run_cli(dir, {"segment", project.string(), "--script", late.string()});
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("op 3 (commit)"), std::string::npos) << refused.err;
  EXPECT_EQ(run_cli(dir, {"objects", project.string(), "--json"}).out, before);
  // Refused before it runs (bad JSON, an unknown op, a misspelt key) or
  // while it runs (a seed off the grid, a lasso of scan 1 used on scan 2).
  for (const std::string& text :
       {std::string("{\"ops\": ["), std::string(R"({"ops": [{"op": "paint"}]})"),
        std::string(R"({"ops": [{"op": "grow", "seed": [0, 0], "tolerence": 3}]})"),
        std::string(R"({"ops": [{"op": "group", "name": "g"}, {"op": "grow", "seed": [0, 99]}]})"),
        std::string(R"({"ops": [{"op": "lasso", "points": [[0, 0], [3, 0], [3, 2]]},
                                {"op": "grow", "seed": [0, 0], "scan": 2}]})")}) {
    const std::filesystem::path bad = write_script(dir, "bad.json", text);
    const CliResult result = run_cli(dir, {"segment", project.string(), "--script", bad.string()});
    EXPECT_EQ(result.exit_code, 2) << text;
    EXPECT_NE(result.err.find("bad.json"), std::string::npos) << result.err;
    EXPECT_EQ(run_cli(dir, {"objects", project.string(), "--json"}).out, before) << text;
  }
}

TEST(Cli, ImportThenInfoJsonDescribesEveryScan) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "site é.sbproj";
  const CliResult import =
      run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string(),
                    fixture("good/ptx/tiny_color.ptx").string()});
  ASSERT_EQ(import.exit_code, 0) << import.err;
  const nlohmann::json info = info_json(dir, project);
  ASSERT_EQ(info["scans"].size(), 3u);
  const nlohmann::json& geo = info["scans"][1];
  EXPECT_EQ(geo["name"], "two_scans-2");
  EXPECT_EQ(geo["rows"], 2);
  EXPECT_EQ(geo["columns"], 2);
  EXPECT_EQ(geo["valid_points"], 4);
  EXPECT_EQ(geo["has_color"], false);
  EXPECT_EQ(geo["has_intensity"], true);
  EXPECT_EQ(geo["angle_model"], "spherical");
  EXPECT_EQ(geo["T_world_scan"].size(), 16u);
  EXPECT_EQ(geo["T_world_scan"][3], 512000.5);  // row-major: translation x
  EXPECT_EQ(info["scans"][2]["has_color"], true);
  for (int k : {0, 1, 2}) EXPECT_LE(geo["bbox_world"][0][k], geo["bbox_world"][1][k]);
}

TEST(Cli, InfoReadsRawScanFilesWithoutAProject) {
  ScratchDir dir;
  const nlohmann::json info = info_json(dir, fixture("good/ptx/two_scans.ptx"));
  EXPECT_EQ(info["scans"].size(), 2u);
}

TEST(Cli, RefusedImportLeavesTheProjectUnchanged) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  const nlohmann::json before = info_json(dir, project);
  // A good file followed by a bad one: neither may be stored.
  const CliResult bad =
      run_cli(dir, {"import", project.string(), fixture("good/ptx/two_scans.ptx").string(),
                    fixture("bad/ptx_truncated_body.ptx").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("ptx_truncated_body.ptx: line 14"), std::string::npos) << bad.err;
  EXPECT_EQ(info_json(dir, project), before);
}

TEST(Cli, E57ImportReportsUnplacedRecordsAndImagesAndExportsBack) {
  ScratchDir dir;
  const std::string project = (dir / "p.sbproj").string();
  const CliResult imported =
      run_cli(dir, {"import", project, fixture("good/e57/structured_spherical.e57").string(),
                    fixture("good/e57/unstructured_cartesian.e57").string()});
  ASSERT_EQ(imported.exit_code, 0) << imported.err;
  EXPECT_THAT(imported.out, ::testing::HasSubstr("2 image(s) stored with the scans"));
  EXPECT_THAT(imported.out, ::testing::HasSubstr("1 record(s) not placed in the scan grids"));
  EXPECT_THAT(imported.out, ::testing::HasSubstr("scattered scans named SCAN-unplaced"));
  const nlohmann::json info = info_json(dir, project);
  ASSERT_EQ(info["scans"].size(), 3u);
  EXPECT_EQ(info["scans"][0]["source"]["unplaced_points"], 1);
  // That record is kept, as a scan of its own beside the grid.
  EXPECT_EQ(info["scans"][1]["name"], "structured-unplaced");
  EXPECT_EQ(info["scans"][1]["valid_points"], 1);
  EXPECT_EQ(info["scans"][1]["layout"], "scattered");
  EXPECT_EQ(info["scans"][2]["source"]["unplaced_points"], 0) << "an unstructured scan keeps all";
  EXPECT_EQ(info["scans"][2]["source"]["points_in_file"], 605);
  EXPECT_EQ(info["scans"][2]["valid_points"], 602) << "all but the 3 records without a return";
  EXPECT_EQ(info["scans"][2]["layout"], "scattered");
  EXPECT_EQ(info["scans"][0]["layout"], "grid");
  EXPECT_EQ(info["scans"][0]["source"]["guid"], "{scan-structured}");
  ASSERT_EQ(info["images"].size(), 2u);
  EXPECT_EQ(info["images"][0]["scan"], 1);
  EXPECT_EQ(info["images"][0]["projection"], "pinhole");
  EXPECT_EQ(info["images"][0]["focal_length"], 0.01);
  EXPECT_EQ(info["images"][0]["T_world_image"][11], 10.5);  // its height, row-major
  EXPECT_GT(info["images"][0]["bytes"], 8);
  EXPECT_TRUE(info["images"][1]["scan"].is_null());
  // One scan exported: its image goes with it, the loose one stays home.
  const std::string one = (dir / "one.e57").string();
  const CliResult exported =
      run_cli(dir, {"export", project, "--format", "e57", "--scan", "1", "-o", one});
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const nlohmann::json back = info_json(dir, one);
  ASSERT_EQ(back["scans"].size(), 1u);
  EXPECT_EQ(back["scans"][0]["valid_points"], info["scans"][0]["valid_points"]);
  ASSERT_EQ(back["images"].size(), 1u);
  EXPECT_EQ(back["images"][0]["name"], "camera 1");
}

TEST(Cli, RefusedE57ImportNamesThePageAndLeavesTheProjectUnchanged) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  const nlohmann::json before = info_json(dir, project);
  const CliResult bad =
      run_cli(dir, {"import", project.string(), fixture("good/e57/georeferenced.e57").string(),
                    fixture("bad/e57_bad_checksum.e57").string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, ::testing::HasSubstr("e57_bad_checksum.e57: (byte 1024), page 1: page fails "
                                            "its CRC-32C checksum"));
  EXPECT_EQ(info_json(dir, project), before);
  const CliResult info = run_cli(dir, {"info", fixture("bad/e57_malformed_xml.e57").string()});
  EXPECT_EQ(info.exit_code, 2);
  EXPECT_THAT(info.err, ::testing::HasSubstr("malformed XML"));
}

TEST(Cli, RefusedImportIntoANewProjectCreatesNoFile) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "new.sbproj";
  EXPECT_EQ(run_cli(dir, {"import", project.string(), fixture("bad/ptx_nan_field.ptx").string()})
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(project));
}

TEST(Cli, UnknownScanFileTypeIsBadInput) {
  ScratchDir dir;
  const std::filesystem::path odd = dir / "scan.xyz";
  std::FILE* f = std::fopen(odd.c_str(), "w");
  std::fputs("1 2 3\n", f);
  std::fclose(f);
  const CliResult result = run_cli(dir, {"import", (dir / "p.sbproj").string(), odd.string()});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("unknown scan file type"), std::string::npos) << result.err;
}

TEST(Cli, ForeignFileIsNotTreatedAsAProject) {
  ScratchDir dir;
  const std::filesystem::path fake = dir / "notes.sbproj";
  std::filesystem::copy_file(fixture("good/ptx/tiny_color.ptx"), fake);
  const std::string bytes = test::read_file_bytes(fake);
  EXPECT_EQ(run_cli(dir, {"info", fake.string()}).exit_code, 2);
  EXPECT_EQ(run_cli(dir, {"import", fake.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            2);
  EXPECT_EQ(test::read_file_bytes(fake), bytes);
}

TEST(Cli, ExportPtxRoundTripsThroughASecondProject) {
  ScratchDir dir;
  const std::filesystem::path first = dir / "a.sbproj", second = dir / "b.sbproj";
  const std::filesystem::path ptx = dir / "export.ptx";
  ASSERT_EQ(run_cli(dir, {"import", first.string(), fixture("good/ptx/two_scans.ptx").string()})
                .exit_code,
            0);
  ASSERT_EQ(
      run_cli(dir, {"export", first.string(), "--format", "ptx", "-o", ptx.string()}).exit_code, 0);
  ASSERT_EQ(run_cli(dir, {"import", second.string(), ptx.string()}).exit_code, 0);
  nlohmann::json a = info_json(dir, first), b = info_json(dir, second);
  for (auto* info : {&a, &b}) {
    for (auto& scan : (*info)["scans"]) {
      scan.erase("source_file");
      scan.erase("name");
      scan.erase("bbox_world");  // recomputed from refitted angles: equal to ~1e-12 m
      // A bound of each file's own round trip, which differs by ~1e-15 m.
      EXPECT_LT(scan["source"]["round_trip_error_m"].get<double>(), 1e-4);
      scan["source"].erase("round_trip_error_m");
    }
  }
  EXPECT_EQ(a, b);
}

// A scan's normals and footprints, exported as PLY and LAS, come back from
// a second project's import and geometry as they were: a cloud keeps the
// normals its scan grid gave it.
TEST(Cli, NormalsAndFootprintsSurviveAPlyAndLasRoundTrip) {
  ScratchDir dir;
  ASSERT_EQ(expect_ok(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(),
                            "--scans", "1", "--columns", "240", "--rows", "60"})
                .exit_code,
            0);
  const std::string first = (dir / "a.sbproj").string(), second = (dir / "b.sbproj").string();
  const auto ok = [&](const std::vector<std::string>& args) { return expect_ok(dir, args); };
  const auto out = [&](const char* name) { return (dir / name).string(); };
  ok({"import", first, (dir / "sim/campus_scan_01.json").string()});
  ok({"geometry", first});
  ok({"export", first, "--format", "ply", "--scan", "1", "-o", out("a.ply")});
  ok({"export", first, "--format", "las", "--scan", "1", "-o", out("a.las")});
  ok({"import", second, out("a.ply"), out("a.las")});
  const CliResult geometry = ok({"geometry", second});
  EXPECT_NE(geometry.out.find("scan 1: "), std::string::npos) << geometry.out;
  EXPECT_NE(geometry.out.find("normals kept as its file recorded them"), std::string::npos);
  ok({"export", second, "--format", "ply", "--scan", "1", "-o", out("b.ply")});
  ok({"export", second, "--format", "las", "--scan", "2", "-o", out("b.las")});
  const auto expect_same_geometry = [](const acquisition::ImportedScan& a,
                                       const acquisition::ImportedScan& b) {
    ASSERT_EQ(a.source.points_in_file, b.source.points_in_file);
    ASSERT_EQ(a.recorded.normal.size(), a.scan.pixel_count());
    ASSERT_EQ(b.recorded.normal.size(), b.scan.pixel_count());
    const Eigen::Matrix3f to_world_a = a.scan.T_world_scan.linear().cast<float>();
    const Eigen::Matrix3f to_world_b = b.scan.T_world_scan.linear().cast<float>();
    std::size_t normals = 0;
    for (std::size_t k = 0; k < a.source.points_in_file; ++k) {
      if (a.recorded.normal[k].isZero()) continue;  // none in the grid: fitted in the cloud
      ++normals;
      EXPECT_LT((to_world_a * a.recorded.normal[k] - to_world_b * b.recorded.normal[k]).norm(),
                1e-5f)
          << k;
      EXPECT_EQ(a.recorded.footprint_m[k], b.recorded.footprint_m[k]) << k;
    }
    EXPECT_GT(normals, a.source.points_in_file * 9 / 10);
  };
  expect_same_geometry(only(acquisition::read_ply(dir / "a.ply")),
                       only(acquisition::read_ply(dir / "b.ply")));
  expect_same_geometry(only(acquisition::read_las(dir / "a.las")),
                       only(acquisition::read_las(dir / "b.las")));
}

TEST(Cli, ExportCsvWritesOneLinePerValidPoint) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj", csv = dir / "points.csv";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"export", project.string(), "--format", "csv", "--scan", "1", "-o",
                          csv.string()})
                .exit_code,
            0);
  const std::string text = test::read_file_bytes(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')), "x,y,z,intensity,r,g,b");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 5);  // header + 5 valid points
}

// Points given in world coordinates near (637012, 8490281, 431) once came
// back from the CSV export 4 cm off; every coordinate must keep 0.1 mm.
TEST(Cli, WorldCoordinatesSurviveImportAndCsvExport) {
  ScratchDir dir;
  const std::filesystem::path ptx = fixture("good/ptx/georef_world_utm.ptx");
  const std::string project = (dir / "p.sbproj").string();
  ASSERT_EQ(run_cli(dir, {"import", project, ptx.string()}).exit_code, 0);
  ASSERT_EQ(run_cli(dir, {"export", project, "--format", "csv", "-o", (dir / "p.csv").string()})
                .exit_code,
            0);
  const auto read_points = [](const std::filesystem::path& path, int skip, char separator) {
    std::istringstream in(test::read_file_bytes(path));
    std::string line;
    for (int k = 0; k < skip; ++k) std::getline(in, line);
    std::vector<std::array<double, 3>> points;
    while (std::getline(in, line)) {
      std::replace(line.begin(), line.end(), separator, ' ');
      std::istringstream fields(line);
      std::array<double, 3> p{};
      if (fields >> p[0] >> p[1] >> p[2]) points.push_back(p);
    }
    std::sort(points.begin(), points.end());
    return points;
  };
  const auto expected = read_points(ptx, 10, ' ');
  const auto exported = read_points(dir / "p.csv", 1, ',');
  ASSERT_EQ(exported.size(), expected.size());
  for (std::size_t k = 0; k < expected.size(); ++k) {
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(exported[k][axis], expected[k][axis], 1e-4) << k << " " << axis;
    }
  }
}

TEST(Cli, ExportOfAMissingScanIdIsBadInput) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  const CliResult result = run_cli(dir, {"export", project.string(), "--format", "ply", "--scan",
                                         "9", "-o", (dir / "x.ply").string()});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.ply"));
}

TEST(Cli, SimulateThenImportThenInfoOnTheCampusSite) {
  ScratchDir dir;
  const CliResult sim =
      run_cli(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(), "--scans", "2",
                    "--columns", "360", "--rows", "90"});
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::filesystem::path project = dir / "campus.sbproj";
  const CliResult import =
      run_cli(dir, {"import", project.string(), (dir / "sim/campus_scan_01.json").string(),
                    (dir / "sim/campus_scan_02.json").string()});
  ASSERT_EQ(import.exit_code, 0) << import.err;
  const nlohmann::json info = info_json(dir, project);
  ASSERT_EQ(info["scans"].size(), 2u);
  EXPECT_EQ(info["scans"][0]["rows"], 90);
  EXPECT_EQ(info["scans"][0]["columns"], 360);
  const nlohmann::json truth = nlohmann::json::parse(test::read_file_bytes(dir / "sim/truth.json"));
  EXPECT_EQ(info["scans"][1]["T_world_scan"], truth["scans"][1]["T_world_scan"]);
}

// --one-sun: every scan under the same sun and sky, each with its own
// exposure and white balance (what a harmonisation should undo exactly).
TEST(Cli, SimulateUnderOneSunVariesOnlyExposureAndWhiteBalance) {
  ScratchDir dir;
  const auto lighting = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {
        "simulate",  "--site", "path",   "--out", (dir / "sim").string(), "--scans", "3",
        "--columns", "72",     "--rows", "18"};
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult sim = run_cli(dir, args);
    EXPECT_EQ(sim.exit_code, 0) << sim.err;
    const nlohmann::json truth =
        nlohmann::json::parse(test::read_file_bytes(dir / "sim/truth.json"));
    std::vector<nlohmann::json> out;
    for (const nlohmann::json& scan : truth["scans"]) out.push_back(scan["lighting"]);
    return out;
  };
  const std::vector<nlohmann::json> own = lighting({});
  const std::vector<nlohmann::json> one = lighting({"--one-sun"});
  ASSERT_EQ(own.size(), 3u);
  ASSERT_EQ(one.size(), 3u);
  EXPECT_NE(own[0]["sun_direction_world"], own[1]["sun_direction_world"]);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(one[k]["sun_direction_world"], one[0]["sun_direction_world"]);
    EXPECT_EQ(one[k]["sky_irradiance"], one[0]["sky_irradiance"]);
    EXPECT_EQ(one[k]["exposure"], own[k]["exposure"]);
    EXPECT_EQ(one[k]["white_balance"], own[k]["white_balance"]);
  }
  EXPECT_NE(one[1]["exposure"], one[0]["exposure"]);
}

TEST(Cli, GeometryThenPlyExportCarriesNormalsAndLeavesMixedPixelsOut) {
  ScratchDir dir;
  ASSERT_EQ(run_cli(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(),
                          "--scans", "1", "--columns", "720", "--rows", "180"})
                .exit_code,
            0);
  const std::filesystem::path project = dir / "p.sbproj", ply = dir / "model.ply";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), (dir / "sim/campus_scan_01.json").string()})
                .exit_code,
            0);
  const CliResult geometry = run_cli(dir, {"geometry", project.string()});
  ASSERT_EQ(geometry.exit_code, 0) << geometry.err;
  EXPECT_NE(geometry.out.find("campus_scan_01"), std::string::npos) << geometry.out;
  ASSERT_EQ(
      run_cli(dir, {"export", project.string(), "--format", "ply", "-o", ply.string()}).exit_code,
      0);
  const std::string bytes = test::read_file_bytes(ply);
  const std::string header = bytes.substr(0, bytes.find("end_header"));
  EXPECT_NE(header.find("property float nx"), std::string::npos);
  EXPECT_NE(header.find("property float radius"), std::string::npos);
  const nlohmann::json info = info_json(dir, project);
  const std::size_t vertices = std::stoul(header.substr(header.find("element vertex ") + 15));
  EXPECT_LT(vertices,
            info["scans"][0]["valid_points"].get<std::size_t>());  // mixed pixels left out
  EXPECT_EQ(
      run_cli(dir, {"geometry", test::fixture("bad/project_not_sqlite.sbproj").string()}).exit_code,
      2);
}

TEST(Cli, UnlevelledAppliesToTheFeatureStageOnly) {
  ScratchDir dir;
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  const CliResult result =
      run_cli(dir, {"register", project.string(), "--coarse", "none", "--unlevelled"});
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.err.find("--unlevelled"), std::string::npos) << result.err;
}

// Two overlapping scans: the merged model leaves out what the finer scan
// also sampled, and before a merge the option is refused without output.
TEST(Cli, MergedExportWritesTheKeptPointsOnly) {
  ScratchDir dir;
  ASSERT_EQ(run_cli(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(),
                          "--scans", "2", "--columns", "720", "--rows", "180"})
                .exit_code,
            0);
  const std::filesystem::path project = dir / "p.sbproj";
  ASSERT_EQ(run_cli(dir, {"import", project.string(), (dir / "sim/campus_scan_01.json").string(),
                          (dir / "sim/campus_scan_02.json").string()})
                .exit_code,
            0);
  ASSERT_EQ(run_cli(dir, {"geometry", project.string()}).exit_code, 0);
  const auto export_csv = [&](const std::string& name, bool merged) {
    std::vector<std::string> args{"export", project.string(),     "--format", "csv",
                                  "-o",     (dir / name).string()};
    if (merged) args.push_back("--merged");
    return run_cli(dir, args);
  };
  const CliResult early = export_csv("early.csv", true);
  EXPECT_EQ(early.exit_code, 2);
  EXPECT_NE(early.err.find("scanbench merge"), std::string::npos) << early.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "early.csv"));
  // Not even one scan fits in a megabyte: refused as a runtime failure, and
  // nothing stored.
  const CliResult starved = run_cli(dir, {"merge", project.string(), "--memory-limit", "1MB"});
  EXPECT_EQ(starved.exit_code, 1);
  EXPECT_NE(starved.err.find("--memory-limit"), std::string::npos) << starved.err;
  EXPECT_EQ(export_csv("early.csv", true).exit_code, 2);

  const CliResult merge = run_cli(dir, {"merge", project.string(), "--json"});
  ASSERT_EQ(merge.exit_code, 0) << merge.err;
  ASSERT_EQ(export_csv("all.csv", false).exit_code, 0);
  ASSERT_EQ(export_csv("merged.csv", true).exit_code, 0);
  const auto lines = [&](const std::string& name) {
    const std::string text = test::read_file_bytes(dir / name);
    return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) - 1;
  };
  const nlohmann::json report = nlohmann::json::parse(merge.out);
  std::size_t kept = 0;
  for (const auto& scan : report["scans"]) kept += scan["kept"].get<std::size_t>();
  EXPECT_EQ(lines("merged.csv"), kept);
  EXPECT_LT(lines("merged.csv"), lines("all.csv"));

  // The level-of-detail store holds the same merged model.
  const CliResult lod = run_cli(dir, {"lod", project.string(), "--json", "--threads", "2"});
  ASSERT_EQ(lod.exit_code, 0) << lod.err;
  const nlohmann::json built = nlohmann::json::parse(lod.out);
  EXPECT_EQ(built["points"].get<std::size_t>(), kept);
  EXPECT_EQ(built["scans"].get<std::size_t>(), 2u);
  EXPECT_TRUE(std::filesystem::exists(dir / "p.sbproj.lod"));
  // A current store is left as it is; a build refused in too little
  // memory leaves the store built before.
  const std::string before = scanbench::test::read_file_bytes(dir / "p.sbproj.lod");
  const CliResult again = run_cli(dir, {"lod", project.string(), "--json"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(nlohmann::json::parse(again.out)["updated"].get<bool>());
  EXPECT_EQ(nlohmann::json::parse(again.out)["nodes_written"], 0);
  EXPECT_EQ(run_cli(dir, {"lod", project.string(), "--rebuild", "--memory-limit", "1kB"}).exit_code,
            1);
  EXPECT_EQ(scanbench::test::read_file_bytes(dir / "p.sbproj.lod"), before);
}

// Every CLI call is a process of its own: undo, redo and history must work
// from what the project file holds, and restore earlier states exactly.
TEST(Cli, UndoRedoAndHistoryWorkAcrossProcesses) {
  ScratchDir dir;
  ASSERT_EQ(run_cli(dir, {"simulate", "--site", "campus", "--out", (dir / "sim").string(),
                          "--scans", "2", "--columns", "240", "--rows", "60", "--pose-error-deg",
                          "1", "--pose-error-m", "0.2"})
                .exit_code,
            0);
  const std::string project = (dir / "p.sbproj").string();
  const auto ok = [&](const std::vector<std::string>& args) { return expect_ok(dir, args); };
  ok({"import", project, (dir / "sim/campus_scan_01.json").string(),
      (dir / "sim/campus_scan_02.json").string()});
  const std::string imported = ok({"info", project, "--json"}).out;
  ok({"geometry", project});
  ok({"register", project, "--coarse", "none"});
  const std::string registered = ok({"info", project, "--json"}).out;
  EXPECT_NE(registered, imported);  // the poses moved
  ok({"merge", project});
  ok({"export", project, "--format", "ply", "--merged", "-o", (dir / "before.ply").string()});
  // The merged model as LAS: as many points as the PLY, point format 7.
  const std::string ply = test::read_file_bytes(dir / "before.ply");
  const std::size_t vertex = ply.find("element vertex ") + 15;
  const std::uint64_t ply_points = std::stoull(ply.substr(vertex, ply.find('\n', vertex) - vertex));
  ok({"export", project, "--format", "las", "--merged", "-o", (dir / "merged.las").string()});
  const std::string las = test::read_file_bytes(dir / "merged.las");
  ASSERT_GE(las.size(), 375u);
  EXPECT_EQ(las.substr(0, 4), "LASF");
  EXPECT_EQ(las[104], 7);
  std::uint64_t las_points = 0;
  std::memcpy(&las_points, las.data() + 247, sizeof las_points);
  EXPECT_EQ(las_points, ply_points);

  const nlohmann::json history = nlohmann::json::parse(ok({"history", project, "--json"}).out);
  ASSERT_EQ(history["commands"].size(), 4u);
  EXPECT_EQ(history["commands"][2]["name"], "register");
  EXPECT_EQ(history["commands"][2]["settings"]["registration"]["coarse"], "none");
  EXPECT_EQ(history["commands"][3]["state"], "done");

  ok({"undo", project});  // merge
  EXPECT_EQ(run_cli(dir, {"export", project, "--format", "ply", "--merged", "-o",
                          (dir / "none.ply").string()})
                .exit_code,
            2);
  ok({"undo", project});  // register
  EXPECT_EQ(ok({"info", project, "--json"}).out, imported);
  ok({"redo", project});
  ok({"redo", project});
  EXPECT_EQ(ok({"info", project, "--json"}).out, registered);
  ok({"export", project, "--format", "ply", "--merged", "-o", (dir / "after.ply").string()});
  EXPECT_EQ(test::read_file_bytes(dir / "after.ply"), test::read_file_bytes(dir / "before.ply"));

  for (int k = 0; k < 4; ++k) ok({"undo", project});
  EXPECT_EQ(info_json(dir, project)["scans"].size(), 0u);
  const CliResult nothing = run_cli(dir, {"undo", project});
  EXPECT_EQ(nothing.exit_code, 2);
  EXPECT_NE(nothing.err.find("nothing to undo"), std::string::npos) << nothing.err;
  for (int k = 0; k < 4; ++k) ok({"redo", project});
  EXPECT_EQ(ok({"info", project, "--json"}).out, registered);
  EXPECT_EQ(run_cli(dir, {"redo", project}).exit_code, 2);
  const std::string table = ok({"history", project}).out;
  EXPECT_NE(table.find("points kept"), std::string::npos) << table;
}

TEST(Cli, SimulateRendersATruthViewAndRefusesABadViewFile) {
  ScratchDir dir;
  const std::filesystem::path view = dir / "view.json", png = dir / "truth.png";
  const char* const good_view = R"({"position": [0, -30, 2], "look_at": [0, 0, 5],
                                    "vertical_fov_deg": 50, "width": 64, "height": 48})";
  std::FILE* f = std::fopen(view.c_str(), "w");
  std::fputs(good_view, f);
  std::fclose(f);
  const CliResult ok = run_cli(
      dir, {"simulate", "--site", "street", "--render-view", view.string(), "-o", png.string()});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(png));
  EXPECT_TRUE(std::filesystem::exists(dir / "truth_object_id.png"));
  f = std::fopen(view.c_str(), "w");
  std::fputs(
      R"({"position": [0, 0, 2], "look_at": [0, 0, 2], "vertical_fov_deg": 50, "width": 64, "height": 48})",
      f);
  std::fclose(f);
  const CliResult bad = run_cli(
      dir, {"simulate", "--site", "street", "--render-view", view.string(), "-o", png.string()});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("look_at"), std::string::npos) << bad.err;
  // The picture is a PNG: it never replaces the view it reads, nor a project.
  const std::string view_before = test::read_file_bytes(view);
  const CliResult over_view = run_cli(
      dir, {"simulate", "--site", "street", "--render-view", view.string(), "-o", view.string()});
  EXPECT_EQ(over_view.exit_code, 2);
  EXPECT_NE(over_view.err.find("must name a .png file"), std::string::npos) << over_view.err;
  EXPECT_EQ(test::read_file_bytes(view), view_before);
  f = std::fopen(view.c_str(), "w");
  std::fputs(good_view, f);
  std::fclose(f);
  const std::filesystem::path project = dir / "project.png";  // a project of any name
  ASSERT_EQ(
      run_cli(dir, {"import", project.string(), test::fixture("good/ptx/tiny_color.ptx").string()})
          .exit_code,
      0);
  const CliResult over_project = run_cli(dir, {"simulate", "--site", "street", "--render-view",
                                               view.string(), "-o", project.string()});
  EXPECT_EQ(over_project.exit_code, 2);
  EXPECT_NE(over_project.err.find("never writes over a project"), std::string::npos)
      << over_project.err;
  EXPECT_EQ(run_cli(dir, {"check", project.string()}).exit_code, 0);
}

TEST(Cli, SimulateWithoutAnOutputFolderIsAUsageError) {
  ScratchDir dir;
  EXPECT_EQ(run_cli(dir, {"simulate", "--site", "campus"}).exit_code, 2);
  EXPECT_EQ(run_cli(dir, {"simulate", "--site", "moon", "--out", dir.path().string()}).exit_code,
            2);
}

}  // namespace
}  // namespace scanbench

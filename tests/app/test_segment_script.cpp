// Segment scripts as one unit: a refused script leaves the journal, its
// redo chain included, exactly as it was, whatever refused it, and no other
// process's write lands in the middle of one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>

#include "app/formats/segment_script.hpp"
#include "core/errors.hpp"
#include "modeling/room_project.hpp"
#include "support/test_support.hpp"

namespace scanbench::app {
namespace {

using modeling::edit_node;
using modeling::NodeEdit;
using modeling::store_room;

using test::ScratchDir;
using ::testing::HasSubstr;

std::filesystem::path write_script(const ScratchDir& dir, const std::string& text) {
  const std::filesystem::path file = dir / "ops.json";
  std::ofstream(file) << text;
  return file;
}

// The journal as a reader sees it: each command's id, name and state.
std::string journal_of(const store::Project& project) {
  std::string out;
  for (const store::CommandRecord& c : project.history())
    out += std::to_string(c.id) + ' ' + c.name + ' ' + std::to_string(static_cast<int>(c.state)) +
           '\n';
  return out;
}

TEST(SegmentScript, ARefusedScriptThatBeganWithUndoKeepsTheUndoneCommandRedoable) {
  const ScratchDir dir;
  const std::filesystem::path file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  store_room(project);
  run_segment_script(project, write_script(dir, R"({"ops": [{"op": "group", "name": "trees"}]})"));
  const std::string journal = journal_of(project);
  const std::int64_t revision = project.revision();
  // Undoes the group, grows and commits (which would end the redo chain),
  // then is refused.
  const std::filesystem::path script = write_script(dir, R"({"ops": [
      {"op": "undo"},
      {"op": "grow", "seed": [600, 100]},
      {"op": "commit", "name": "x"},
      {"op": "hide", "node": "no such node"}]})");
  try {
    run_segment_script(project, script);
    FAIL() << "a script hiding a node that is not there ran";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("op 4 (hide)"));
    EXPECT_THAT(error.what(), HasSubstr("the script stored nothing"));
  }
  EXPECT_EQ(journal_of(project), journal);
  EXPECT_EQ(project.revision(), revision);
  ASSERT_EQ(project.object_nodes().size(), 1u);
  // The group is still the newest command: undo takes it, redo brings it back.
  const std::optional<store::CommandRecord> undone = project.undo();
  ASSERT_TRUE(undone);
  EXPECT_EQ(undone->name, "group");
  const std::optional<store::CommandRecord> redone = project.redo();
  ASSERT_TRUE(redone);
  EXPECT_EQ(redone->id, undone->id);
  EXPECT_EQ(project.object_nodes().size(), 1u);
}

// In a script as in the workbench, a grow is session state: undo takes it
// back before any command, and the selection the script leaves is kept in
// the project, for the next script to commit.
TEST(SegmentScript, UndoTakesBackAGrowAndTheLeftSelectionIsKept) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  store_room(project);
  run_segment_script(project, write_script(dir, R"({"ops": [{"op": "group", "name": "trees"}]})"));
  const SegmentScriptResult grown = run_segment_script(project, write_script(dir, R"({"ops": [
      {"op": "grow", "seed": [600, 100]},
      {"op": "add", "seed": [100, 100]},
      {"op": "undo"}]})"));
  ASSERT_EQ(grown.ops.size(), 3u);
  EXPECT_TRUE(grown.ops[2]["command"].is_null());
  EXPECT_EQ(grown.ops[2]["result"]["undid"], "grow");
  EXPECT_EQ(project.object_nodes().size(), 1u);  // the group stays
  ASSERT_NE(grown.kept_selections, 0);
  EXPECT_EQ(project.history().back().name, "keep_selection");
  const SegmentScriptResult committed = run_segment_script(
      project, write_script(dir, R"({"ops": [{"op": "commit", "name": "wall"}]})"));
  EXPECT_EQ(committed.kept_selections, 0);
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  ASSERT_EQ(nodes.size(), 2u);
  EXPECT_EQ(nodes[1].points, grown.ops[0]["result"]["selected_pixels"].get<std::int64_t>());
}

TEST(SegmentScript, AScriptIsWholeWhileAnotherProcessWrites) {
  const ScratchDir dir;
  const std::filesystem::path file = dir / "p.sbproj";
  store::Project project = store::Project::create(file);
  store_room(project);
  run_segment_script(project, write_script(dir, R"({"ops": [{"op": "group", "name": "other"}]})"));
  std::string ops = R"({"op": "grow", "seed": [600, 100]}, {"op": "commit", "name": "floor"},)";
  for (int k = 0; k < 22; ++k) ops += R"({"op": "group", "name": "g)" + std::to_string(k) + "\"},";
  const std::filesystem::path script =
      write_script(dir, R"({"ops": [)" + ops + R"({"op": "hide", "node": "other"}]})");
  // Another connection renames the group over and over while the scripts
  // run: its writes wait for a script (or are refused, when the script
  // committed while they computed), and none lands inside one.
  std::atomic<bool> done = false;
  std::atomic<int> renames = 0;
  std::thread other([&] {
    store::Project writer = store::Project::open(file);
    for (int k = 0; !done; ++k) {
      NodeEdit edit;
      edit.node = writer.nodes_named("other").front();
      edit.hidden = k % 2 == 0;
      try {
        edit_node(writer, edit);
        ++renames;
      } catch (const core::RuntimeFailure&) {
        // "the project's objects changed while edit was computing": nothing stored
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  });
  const auto wait_for_renames = [&renames](int at_least) {
    while (renames < at_least) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  wait_for_renames(1);
  const SegmentScriptResult result = run_segment_script(project, script);
  // A script refused at its last op while the other writes: none of its
  // groups stays.
  const int before_refused = renames;
  std::string refused = R"({"ops": [)";
  for (int k = 0; k < 10; ++k) refused += R"({"op": "group", "name": "refused"},)";
  refused += R"({"op": "hide", "node": "no such node"}]})";
  EXPECT_THROW(run_segment_script(project, write_script(dir, refused)), core::InputError);
  wait_for_renames(before_refused + 1);
  done = true;
  other.join();
  EXPECT_TRUE(project.nodes_named("refused").empty());
  ASSERT_EQ(result.ops.size(), 25u);
  // The script's commands follow each other in the journal, with no other
  // command between them.
  std::vector<std::int64_t> script_commands;
  for (const nlohmann::json& op : result.ops) {
    if (!op["command"].is_null()) script_commands.push_back(op["command"]);  // a grow is none
  }
  const std::vector<store::CommandRecord> history = project.history();
  const auto first =
      std::find_if(history.begin(), history.end(),
                   [&](const store::CommandRecord& c) { return c.id == script_commands.front(); });
  ASSERT_NE(first, history.end());
  for (std::size_t k = 0; k < script_commands.size(); ++k) {
    ASSERT_LT(first + static_cast<std::ptrdiff_t>(k), history.end());
    EXPECT_EQ((first + static_cast<std::ptrdiff_t>(k))->id, script_commands[k]) << k;
  }
  EXPECT_EQ(project.object_nodes().size(), 24u);
}

}  // namespace
}  // namespace scanbench::app

// The workbench's recorder (app/workbench/replay.hpp) as a live session
// drives it: several events in one frame, moves coalesced to the frame's
// last, frames without events written as waits, and the presses a running
// command does not take left out, so that the file replays what the
// workbench acted on.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/workbench/replay.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

using app::workbench::ReplayRecorder;
using nlohmann::json;

// What reaches the workbench behind the recorder, one line per event.
struct Listener final : render::WindowInput {
  std::vector<std::string> seen;
  void cursor_moved(double x, double y) override {
    seen.push_back("move " + std::to_string(static_cast<int>(x)) + " " +
                   std::to_string(static_cast<int>(y)));
  }
  void button(int button, bool pressed, int) override {
    seen.push_back((pressed ? "press " : "release ") + std::to_string(button));
  }
  void scrolled(double, double dy) override { seen.push_back("scroll " + std::to_string(dy)); }
  void key(int key, bool pressed, int) override {
    seen.push_back((pressed ? "key down " : "key up ") + std::to_string(key));
  }
  void text(unsigned codepoint) override { seen.push_back("text " + std::to_string(codepoint)); }
};

TEST(ReplayRecorder, WritesWhatALiveSessionActedOn) {
  const test::ScratchDir dir;
  const std::filesystem::path file = dir / "session.json";
  Listener listener;
  bool command_running = false;
  ReplayRecorder recorder(listener, file, [&] { return !command_running; });
  // Frame 1: the cursor moves twice, then a click, all before the frame ends.
  recorder.cursor_moved(10, 20);
  recorder.cursor_moved(30, 40);
  recorder.button(0, true, 0);
  recorder.button(0, false, 0);
  recorder.next_frame();
  // A command runs: a press, a key, the wheel and text are not taken; a
  // move and a release are (the cursor and the buttons stay true). The
  // caller counts no frames meanwhile.
  command_running = true;
  recorder.button(1, true, 0);
  recorder.key('Z', true, render::keys::kModControl);
  recorder.scrolled(0, 1);
  recorder.text('a');
  recorder.cursor_moved(50, 60);
  recorder.button(1, false, 0);
  command_running = false;
  // Three idle frames, then Ctrl+Z.
  recorder.next_frame();
  recorder.next_frame();
  recorder.next_frame();
  recorder.key('Z', true, render::keys::kModControl);
  recorder.save();

  const std::vector<std::string> passed_on = {"move 10 20", "move 30 40", "press 0",    "release 0",
                                              "move 50 60", "release 1",  "key down 90"};
  EXPECT_EQ(listener.seen, passed_on);
  std::ifstream in(file);
  const json written = json::parse(in);
  const json expected = json::parse(R"({"events": [
      {"move": [30.0, 40.0]}, {"press": "left"}, {"release": "left"},
      {"move": [50.0, 60.0]}, {"release": "right"},
      {"wait": 2}, {"key_down": "Z", "mods": ["ctrl"]}]})");
  EXPECT_EQ(written, expected) << written.dump();
  // And the file reads back as a replay.
  const std::vector<app::workbench::ReplayEvent> replayed = app::workbench::read_replay(file);
  ASSERT_EQ(replayed.size(), 7u);  // the wait of two frames is one event
  EXPECT_EQ(replayed[5].kind, app::workbench::ReplayEvent::Kind::kWait);
  EXPECT_EQ(replayed[5].frames, 2);
}

}  // namespace
}  // namespace scanbench

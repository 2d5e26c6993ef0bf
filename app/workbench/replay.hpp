// Recorded input for `scanbench workbench --replay EVENTS.json`: mouse and
// key events fed, one per frame, through the window's input listener, the
// path live input takes. The file:
//
//   {"events": [
//     {"move": [x, y]},                          the cursor [window pixels]
//     {"press": "left"}, {"release": "left"},    buttons: left, right, middle
//     {"click": [x, y], "button": "left", "mods": ["ctrl"]},  move, press, release
//     {"drag": [[x0, y0], [x1, y1]], "button": "left", "steps": 10},
//     {"scroll": 1.0, "at": [x, y]},             wheel steps (positive: away from the user)
//     {"key": "Z", "mods": ["ctrl"]},           press and release; names below
//     {"hold": "W", "frames": 20},               held down for that many frames
//     {"text": "north wall"},                    typed characters
//     {"wait": 3},                               frames without input
//     {"screenshot": "step.png"}]}               relative to the events file's folder
//
// Keys: A–Z, 0–9, Enter, Escape, Tab, Backspace, Delete, Left, Right, Up,
// Down, Home, End, Space. Mods: ctrl, shift, alt.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace scanbench::app::workbench {

struct ReplayEvent {
  enum class Kind { kMove, kButton, kScroll, kKey, kText, kWait, kScreenshot };
  Kind kind = Kind::kWait;
  double x = 0.0;
  double y = 0.0;
  int button = 0;
  int key = 0;
  bool pressed = false;
  int mods = 0;
  double scroll = 0.0;
  unsigned codepoint = 0;
  std::filesystem::path file;
};

// The events in the order they are fed (a click is a move, a press and a
// release; a drag its moves in between). Throws core::InputError naming the
// file, the event ("events[3]") and the problem.
std::vector<ReplayEvent> read_replay(const std::filesystem::path& file);

}  // namespace scanbench::app::workbench

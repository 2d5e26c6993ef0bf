// Recorded input for `scanbench workbench --replay EVENTS.json`: mouse and
// key events fed, one per frame, through the window's input listener, the
// path live input takes. The file:
//
//   {"events": [
//     {"move": P},                               the cursor
//     {"press": "left"}, {"release": "left"},    buttons: left, right, middle
//     {"click": P, "button": "left", "mods": ["ctrl"]},  move, press, release
//     {"drag": [P0, P1], "button": "left", "steps": 10},
//     {"scroll": 1.0, "at": P},                  wheel steps (positive: away from the user)
//     {"key": "Z", "mods": ["ctrl"]},           press and release; names below
//     {"key_down": "W"}, {"key_up": "W"},        press or release alone
//     {"hold": "W", "frames": 20},               held down for that many frames
//     {"text": "north wall"},                    typed characters
//     {"wait": 3},                               frames without input
//     {"screenshot": "step.png"},                relative to the events file's folder
//     {"layout": "step.json"}]}                  as --layout writes it, at that point
//
// A place P is window pixels [x, y], or where something is drawn when the
// event is fed (so that a replay needs no layout written beforehand):
//   "apply colour"                               a named widget's centre (--layout lists them)
//   {"widget": "hue", "offset": [55, 0]}         that, moved by window pixels
//   {"pixel": [654, 116]}                        a scan pixel's centre (column, row) in the
//                                                panoramic view
//   {"view3d": [0.5, 0.5]}                       a point of the 3D view, in fractions of its
//                                                width and height from its top left
// Any of the three objects takes an "offset". A drag finds both its ends
// when it starts. A place not drawn in that frame (a widget of a panel
// closed, no scan shown) stops the replay with an error naming the event.
//
// Keys: A–Z, 0–9, Enter, Escape, Tab, Backspace, Delete, Left, Right, Up,
// Down, Home, End, Space. Mods: ctrl, shift, alt.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "render/window/window_device.hpp"

namespace scanbench::app::workbench {

// A place a pointer event goes to (P above).
struct ReplayPlace {
  enum class Kind { kWindow, kWidget, kPixel, kView3d };
  Kind kind = Kind::kWindow;
  std::string widget;                 // kWidget: its name
  std::array<double, 2> at = {};      // kWindow: window pixels; kPixel: column, row;
                                      // kView3d: fractions of the view
  std::array<double, 2> offset = {};  // window pixels, added
};

struct ReplayEvent {
  enum class Kind { kMove, kButton, kScroll, kKey, kText, kWait, kScreenshot, kLayout };
  Kind kind = Kind::kWait;
  // The file's entry this event comes from (events[entry]).
  std::size_t entry = 0;
  // kMove: the cursor goes to `from` + t × (`to` − `from`) (a drag's steps),
  // the places found once per entry. x, y: where, once found.
  ReplayPlace from;
  ReplayPlace to;
  double t = 0.0;
  double x = 0.0;
  double y = 0.0;
  int button = 0;
  int key = 0;
  bool pressed = false;
  int mods = 0;
  double scroll = 0.0;
  unsigned codepoint = 0;
  int frames = 1;              // kWait: frames that pass without input
  std::filesystem::path file;  // kScreenshot, kLayout
};

// The events in the order they are fed (a click is a move, a press and a
// release; a drag its moves in between; a wait or a hold's frames one
// event). Throws core::InputError naming the
// file, the event ("events[3]") and the problem.
std::vector<ReplayEvent> read_replay(const std::filesystem::path& file);

// A key's code (render::keys) by its name above, and back; none for keys
// the format does not name.
std::optional<int> key_code(const std::string& name);
std::optional<std::string> key_name(int code);

// Records what reaches the window's input listener as a replay file
// (`scanbench workbench --record FILE`), passing every event on to
// `inner`. Each frame's events are written in order, and the frames between
// them as waits, so that the file replayed feeds the same input in the same
// order (a replay feeds one event a frame; of a frame's cursor moves only
// the last is kept). Modifier keys and keys the format does not name are
// not written: every event carries its modifiers. While `takes_presses`
// says no (a background command runs), presses, the wheel and text are
// neither passed on nor written, and frames are not counted: a replay waits
// for each command to end before it feeds the next event.
class ReplayRecorder final : public render::WindowInput {
 public:
  ReplayRecorder(render::WindowInput& inner, std::filesystem::path file,
                 std::function<bool()> takes_presses);

  // A frame has ended (the caller leaves out frames drawn while a command ran).
  void next_frame() { ++frames_since_event_; }
  // Writes the file, whole or not at all. Throws core::RuntimeFailure when
  // it cannot be written.
  void save() const;

  void cursor_moved(double x, double y) override;
  void button(int button, bool pressed, int mods) override;
  void scrolled(double dx, double dy) override;
  void key(int key, bool pressed, int mods) override;
  void text(unsigned codepoint) override;

 private:
  // Appends an event, after a wait for the frames since the last one.
  void add(nlohmann::json event, int mods);

  render::WindowInput& inner_;
  std::filesystem::path file_;
  std::function<bool()> takes_presses_;
  nlohmann::json events_ = nlohmann::json::array();
  int frames_since_event_ = 0;
  bool moved_this_frame_ = false;
};

}  // namespace scanbench::app::workbench

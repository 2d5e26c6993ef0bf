// The workbench's input layer: window events (live from GLFW, or fed from
// a replay, one path for both) become ImGui's input and, where ImGui does
// not want them, the tools' clicks in the panoramic view, the camera's
// moves in the 3D view, and the keyboard shortcuts.
#pragma once

#include "app/workbench/replay.hpp"
#include "app/workbench/workbench_state.hpp"
#include "render/window/window_device.hpp"

namespace scanbench::app::workbench {

class WorkbenchInput final : public render::WindowInput {
 public:
  // Installs the key map in ImGui's io (an ImGui context must exist).
  explicit WorkbenchInput(WorkbenchState& state);

  void cursor_moved(double x, double y) override;
  void button(int button, bool pressed, int mods) override;
  void scrolled(double dx, double dy) override;
  void key(int key, bool pressed, int mods) override;
  void text(unsigned codepoint) override;

  // Whether presses, the wheel and text act now: not while a background
  // command runs (only moves and releases are taken then, so that the
  // cursor and the keys held stay true). A recorder leaves out what is
  // not taken: replayed, it would act once the command has ended.
  bool takes_presses() const { return !state_.command.running() && !state_.command.asked(); }

  // Walk/fly: moves the camera by the keys held for `seconds`.
  void fly_keys(double seconds);

 private:
  // ImGui's modifier state: the modifier keys held, and `mods` of the event.
  void set_mods(int mods);
  // Shortcuts: Ctrl+Z / Ctrl+Y through the journal, letters for the tools.
  void shortcut(int key, int mods);

  WorkbenchState& state_;
};

// Feeds one replay event through `input`, as the window would.
void feed(render::WindowInput& input, const ReplayEvent& event);

}  // namespace scanbench::app::workbench

#include "app/workbench/input.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace scanbench::app::workbench {

namespace keys = render::keys;

WorkbenchInput::WorkbenchInput(WorkbenchState& state) : state_(state) {
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  const std::array<std::pair<ImGuiKey, int>, 19> map = {{{ImGuiKey_Tab, keys::kTab},
                                                         {ImGuiKey_LeftArrow, keys::kLeft},
                                                         {ImGuiKey_RightArrow, keys::kRight},
                                                         {ImGuiKey_UpArrow, keys::kUp},
                                                         {ImGuiKey_DownArrow, keys::kDown},
                                                         {ImGuiKey_Home, keys::kHome},
                                                         {ImGuiKey_End, keys::kEnd},
                                                         {ImGuiKey_Delete, keys::kDelete},
                                                         {ImGuiKey_Backspace, keys::kBackspace},
                                                         {ImGuiKey_Space, keys::kSpace},
                                                         {ImGuiKey_Enter, keys::kEnter},
                                                         {ImGuiKey_Escape, keys::kEscape},
                                                         {ImGuiKey_KeyPadEnter, keys::kEnter},
                                                         {ImGuiKey_A, 'A'},
                                                         {ImGuiKey_C, 'C'},
                                                         {ImGuiKey_V, 'V'},
                                                         {ImGuiKey_X, 'X'},
                                                         {ImGuiKey_Y, 'Y'},
                                                         {ImGuiKey_Z, 'Z'}}};
  for (const auto& [imgui_key, code] : map) io.KeyMap[imgui_key] = code;
}

void WorkbenchInput::cursor_moved(double x, double y) {
  WorkbenchState& s = state_;
  ImGui::GetIO().MousePos = ImVec2(static_cast<float>(x), static_cast<float>(y));
  const double dx = x - s.cursor[0], dy = y - s.cursor[1];
  s.cursor = {x, y};
  if (s.drag == Drag::kOrbit) {
    if (s.fly) {
      s.navigation.look(dx, dy);
    } else {
      s.navigation.orbit(dx, dy);
    }
    s.view_dirty = true;
  } else if (s.drag == Drag::kPan3d) {
    s.navigation.pan(dx, dy, s.view3d.h);
    s.view_dirty = true;
  } else if (s.drag == Drag::kPanPanorama) {
    s.pan[0] += static_cast<float>(dx);
    s.pan[1] += static_cast<float>(dy);
  } else if (s.drag == Drag::kLasso3d) {
    s.extend_lasso_3d(x, y);
  } else if (s.drag == Drag::kBrush3d && s.view3d.contains(x, y)) {
    s.brush_at(x, y);
  }
}

void WorkbenchInput::button(int button, bool pressed, int mods) {
  WorkbenchState& s = state_;
  ImGuiIO& io = ImGui::GetIO();
  if (!takes_presses()) {
    // A command runs: a release lets the button go, and does nothing else
    // (no pick, no drag: the command's start ended any).
    if (pressed) return;
    set_mods(0);
    if (button >= 0 && button < 5) io.MouseDown[button] = false;
    s.drag = Drag::kNone;
    return;
  }
  set_mods(pressed ? mods : 0);
  if (button >= 0 && button < 5) io.MouseDown[button] = pressed;
  if (!pressed) {
    if (s.drag == Drag::kLasso3d || s.drag == Drag::kBrush3d) {
      const Drag ended = s.drag;
      s.drag = Drag::kNone;
      if (ended == Drag::kLasso3d) {
        s.finish_lasso_3d();
      } else {
        s.finish_brush();
      }
      return;
    }
    // Measuring, a left click that did not drag picks a point.
    const bool clicked =
        s.drag == Drag::kOrbit && button == 0 &&
        std::hypot(s.cursor[0] - s.press_at[0], s.cursor[1] - s.press_at[1]) < s.px(3);
    s.drag = Drag::kNone;
    if (clicked && !s.fly) {
      if (s.measuring) {
        s.pick_at(s.cursor[0], s.cursor[1]);
      } else {
        s.select_in_3d(s.cursor[0], s.cursor[1], (mods & keys::kModControl) != 0);
      }
    }
    return;
  }
  if (io.WantCaptureMouse) return;  // the panels have it
  const auto [x, y] = s.cursor;
  if (s.panorama.contains(x, y)) {
    if (button == 0 && s.measuring) {
      const auto [image_x, image_y] = s.panorama_pixel(x, y);
      s.pick_in_panorama(image_x, image_y);
    } else if (button == 0) {
      const auto [image_x, image_y] = s.panorama_pixel(x, y);
      // A seed grows a region beside the window; a lasso or barrier vertex
      // is added at once (clicks in quick succession each count).
      if (s.session.tool == Tool::kSeed) {
        s.run("Growing the selection", [&s, x = image_x, y = image_y] { s.session.click(x, y); });
      } else {
        s.session.click(image_x, image_y);
      }
    } else {
      s.drag = Drag::kPanPanorama;
    }
  } else if (s.view3d.contains(x, y)) {
    s.press_at = s.cursor;
    // The lasso and the brush select with the left button; the middle one
    // then turns the view, and the right one still pans.
    const bool tool_3d = (s.session.tool == Tool::kLasso || s.session.tool == Tool::kBrush) &&
                         !s.measuring && !s.fly;
    if (tool_3d && button == 0 && s.session.tool == Tool::kLasso) {
      s.drag = Drag::kLasso3d;
      s.start_lasso_3d(x, y, (mods & keys::kModShift) != 0);
    } else if (tool_3d && button == 0) {
      s.drag = Drag::kBrush3d;
      s.brushed.clear();
      s.selection_marks.clear();
      s.brush_at(x, y);
    } else if (tool_3d && button == 2) {
      s.drag = Drag::kOrbit;
    } else {
      s.drag = button == 0 ? Drag::kOrbit : Drag::kPan3d;
    }
  }
}

void WorkbenchInput::scrolled(double, double dy) {
  WorkbenchState& s = state_;
  if (!takes_presses()) return;
  ImGuiIO& io = ImGui::GetIO();
  io.MouseWheel += static_cast<float>(dy);
  if (io.WantCaptureMouse) return;
  const auto [x, y] = s.cursor;
  if (s.panorama.contains(x, y)) {
    // Zoom about the cursor: the pixel under it stays under it.
    const auto [image_x, image_y] = s.panorama_pixel(x, y);
    s.zoom = std::clamp(s.zoom * static_cast<float>(std::pow(1.25, dy)), 1.0f, 64.0f);
    const ImVec2 moved = s.panorama_screen({image_x, image_y});  // where the new zoom put it
    s.pan[0] += static_cast<float>(x) - moved.x;
    s.pan[1] += static_cast<float>(y) - moved.y;
  } else if (s.view3d.contains(x, y)) {
    s.navigation.zoom(dy);
    s.view_dirty = true;
  }
}

void WorkbenchInput::key(int key, bool pressed, int mods) {
  if (pressed && !takes_presses()) return;
  ImGuiIO& io = ImGui::GetIO();
  if (key >= 0 && key < 512) io.KeysDown[key] = pressed;
  if (pressed) {
    state_.held.insert(key);
  } else {
    state_.held.erase(key);
  }
  // A key's modifiers hold while it is down; after that only the
  // modifier keys still held count (a replayed Ctrl+Z lets Ctrl go).
  set_mods(pressed ? mods : 0);
  if (!pressed || io.WantTextInput) return;
  shortcut(key, mods);
}

void WorkbenchInput::shortcut(int key, int mods) {
  WorkbenchState& s = state_;
  if (s.question) return;  // answered first, in its window
  // Undo and redo work wherever the keyboard is, text fields excepted
  // (they have their own).
  const bool control = (mods & keys::kModControl) != 0;
  const bool shift = (mods & keys::kModShift) != 0;
  if (control && (key == 'Z' || key == 'Y')) {
    if (key == 'Z' && !shift) {
      s.undo();
    } else {
      s.redo();
    }
    return;
  }
  // Letter shortcuts act unless a text field has the keyboard (not "any
  // widget": a click on a tree node would otherwise swallow the next key).
  if (control) return;
  switch (key) {
    case 'S':
      s.session.tool = Tool::kSeed;
      break;
    case 'L':
      s.session.tool = Tool::kLasso;
      break;
    case 'B':
      s.session.tool = Tool::kBarrier;
      break;
    case 'R':
      s.session.tool = Tool::kBrush;
      break;
    case keys::kEnter:
      if (s.measuring) s.finish_measurement();
      s.session.finish_polyline();
      break;
    case keys::kEscape:
      s.session.clear_constraints();
      break;
    case 'C':
      s.commit();
      break;
    case 'G':
      s.group();
      break;
    case 'F':
      s.frame_selection();
      break;
    case 'M':
      s.measuring = !s.measuring;
      s.picks.clear();
      break;
    case 'V':
      s.fly = !s.fly;
      break;
    default:
      break;
  }
}

void WorkbenchInput::text(unsigned codepoint) {
  if (!takes_presses()) return;
  ImGui::GetIO().AddInputCharacter(codepoint);
}

void WorkbenchInput::set_mods(int mods) {
  ImGuiIO& io = ImGui::GetIO();
  const auto held = [&](int left, int right) {
    return state_.held.count(left) != 0 || state_.held.count(right) != 0;
  };
  io.KeyCtrl = held(keys::kLeftControl, keys::kRightControl) || (mods & keys::kModControl) != 0;
  io.KeyShift = held(keys::kLeftShift, keys::kRightShift) || (mods & keys::kModShift) != 0;
  io.KeyAlt = held(keys::kLeftAlt, keys::kRightAlt) || (mods & keys::kModAlt) != 0;
}

void WorkbenchInput::fly_keys(double seconds) {
  WorkbenchState& s = state_;
  if (!s.fly || ImGui::GetIO().WantTextInput) return;
  const auto held = [&](int key) { return s.held.count(key) ? 1.0 : 0.0; };
  const double forward = held('W') - held('S');
  const double right = held('D') - held('A');
  const double up = held('E') - held('Q');
  if (forward == 0.0 && right == 0.0 && up == 0.0) return;
  s.navigation.fly(forward, right, up, seconds);
  s.view_dirty = true;
}

void feed(render::WindowInput& input, const ReplayEvent& event) {
  using Kind = ReplayEvent::Kind;
  switch (event.kind) {
    case Kind::kMove:
      input.cursor_moved(event.x, event.y);
      break;
    case Kind::kButton:
      input.button(event.button, event.pressed, event.mods);
      break;
    case Kind::kScroll:
      input.scrolled(0.0, event.scroll);
      break;
    case Kind::kKey:
      input.key(event.key, event.pressed, event.mods);
      break;
    case Kind::kText:
      input.text(event.codepoint);
      break;
    case Kind::kWait:
    case Kind::kScreenshot:
    case Kind::kLayout:
      break;
  }
}

}  // namespace scanbench::app::workbench

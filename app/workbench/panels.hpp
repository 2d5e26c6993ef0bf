// The workbench's panels and views, one file each: what they show comes
// from the shared state, what they do goes through it (the session's
// commands, the camera). The frame loop (workbench.cpp) draws them in
// order, each frame.
#pragma once

#include <imgui.h>

#include <functional>
#include <optional>

#include "app/workbench/workbench_state.hpp"

namespace scanbench::app::workbench {

// The project panel's sections, inside its window (workbench.cpp):
void scans_panel(WorkbenchState& s);          // the scans; the shown one's pose
void objects_panel(WorkbenchState& s);        // the object tree and its commands
void proposals_panel(WorkbenchState& s);      // automatic proposals under review
void color_panel(WorkbenchState& s);          // the selected object's colour edit
void view_settings_panel(WorkbenchState& s);  // how the 3D view draws
void measure_panel(WorkbenchState& s);        // clip box, slice; measurements: picks, list, CSV

// Windows of their own:
void toolbar_panel(WorkbenchState& s);    // tools, channel, tolerance, name, commit, undo
void status_panel(WorkbenchState& s);     // what the last action did, the 3D frame's figures
void questions_panel(WorkbenchState& s);  // the question being asked, modal
// While a command runs, over the frozen frame: what runs, for how long.
void command_progress_panel(const WorkbenchState& s);

// Views, drawn behind the panels; input reaches them when ImGui does not
// want it (input.hpp).
void panorama_view(WorkbenchState& s);
void view_3d(WorkbenchState& s);
// The measurements and the points being picked, over a view: `at` gives a
// world point's place in the window (none where the view does not show
// it); a line longer than `longest_line` is not drawn (a panorama's seam).
void measurement_overlay(WorkbenchState& s, ImDrawList* draw,
                         const std::function<std::optional<ImVec2>(const Eigen::Vector3d&)>& at,
                         float longest_line);

// A fixed window at (x, y) of w × h pixels.
inline void place_window(float x, float y, float w, float h) {
  ImGui::SetNextWindowPos(ImVec2(x, y));
  ImGui::SetNextWindowSize(ImVec2(w, h));
}

inline constexpr ImGuiWindowFlags kFixedWindow =
    ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;

}  // namespace scanbench::app::workbench

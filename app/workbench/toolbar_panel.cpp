#include <algorithm>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

// The channel a seed grows on and its tolerance (the seed tool's only).
void seed_settings(WorkbenchState& s) {
  Session& session = s.session;
  // An unstructured cloud has no range image to grow on.
  ImGui::BeginDisabled(!session.has_grid());
  ImGui::SetNextItemWidth(s.px(100));
  int channel = static_cast<int>(session.channel);
  if (ImGui::Combo("##channel", &channel, "range\0colour\0intensity\0normal\0")) {
    session.channel = static_cast<segmentation::Channel>(channel);
    session.tolerance = segmentation::default_grow_settings(session.channel).tolerance;
  }
  s.probe("channel");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(s.px(90));
  float tolerance = static_cast<float>(session.tolerance);
  // Units by channel (region_grow.hpp): range in footprints, colour in
  // ΔE, intensity in shares of the scan's spread, normal in degrees.
  if (ImGui::DragFloat("tolerance", &tolerance, 0.01f * std::max(tolerance, 0.01f), 0.001f, 100.0f,
                       "%.3g"))
    session.tolerance = tolerance;
  ImGui::SameLine();
  ImGui::EndDisabled();
}

// The first row: the tool, its settings (a seed's channel and tolerance,
// the 3D lasso's depth, the brush's radius), and how a selection joins
// the selection so far.
void tools_row(WorkbenchState& s) {
  Session& session = s.session;
  // The lasso and the brush select in the 3D view, whatever the scans.
  int tool = static_cast<int>(session.tool);
  ImGui::RadioButton("seed (S)", &tool, 0);
  s.probe("tool seed");
  ImGui::SameLine();
  ImGui::RadioButton("lasso (L)", &tool, 1);
  s.probe("tool lasso");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "In the panorama: click the vertices of a lasso that bounds the grows.\n"
        "In the 3D view: drag to select what it encloses (Shift: a box).");
  ImGui::SameLine();
  ImGui::RadioButton("barrier (B)", &tool, 2);
  s.probe("tool barrier");
  ImGui::SameLine();
  ImGui::RadioButton("brush (R)", &tool, 3);
  s.probe("tool brush");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("In the 3D view: drag over surfaces to select the points within the radius");
  session.tool = static_cast<Tool>(tool);
  ImGui::SameLine();
  if (session.tool == Tool::kLasso) {
    ImGui::Checkbox("through", &s.select_through);
    s.probe("select through");
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("The 3D lasso takes every depth, not only what is in front");
    if (!s.select_through) {
      ImGui::SameLine();
      ImGui::SetNextItemWidth(s.px(70));
      ImGui::DragFloat("depth", &s.select_depth_m, 0.05f, 0.0f, 50.0f, "%.1f m");
      s.probe_slider("select depth");
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "How far behind the surface in front the 3D lasso reaches\n"
            "(0: only what you see; a tree's depth: its leaves inside)");
    }
  } else if (session.tool == Tool::kBrush) {
    ImGui::SetNextItemWidth(s.px(80));
    ImGui::DragFloat("radius", &s.brush_radius_m, 0.01f, 0.02f, 10.0f, "%.2f m");
    s.probe_slider("brush radius");
  }
  ImGui::SameLine();
  if (session.tool == Tool::kSeed) seed_settings(s);
  int mode = static_cast<int>(session.mode);
  ImGui::RadioButton("new", &mode, 0);
  ImGui::SameLine();
  ImGui::RadioButton("add", &mode, 1);
  s.probe("mode add");
  ImGui::SameLine();
  ImGui::RadioButton("subtract", &mode, 2);
  session.mode = static_cast<modeling::SelectMode>(mode);
}

// The second row: the name for commits, groups and renames, commit,
// proposals, the panoramic view's channel, undo and redo, and clearing
// the panorama's lasso and barriers.
void commands_row(WorkbenchState& s) {
  ImGui::SetNextItemWidth(s.px(220));
  if (ImGui::InputText("name", s.name.data(), s.name.size(),
                       ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll))
    s.commit();
  s.probe("name");
  ImGui::SameLine();
  const bool read_only = s.session.read_only();
  ImGui::BeginDisabled(s.session.selected_pixels() == 0 || read_only);
  if (ImGui::Button("Commit (C)")) s.commit();
  s.probe("commit");
  ImGui::SameLine();
  // The selection is session state, kept when the workbench closes: Keep
  // stores it now, for another process (a segment script) to go on with.
  if (ImGui::Button("Keep")) s.run("Keeping the selection", [&s] { s.session.keep_selections(); });
  s.probe("keep selection");
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("Keep the selection in the project now (it is kept when you close)");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(read_only || !s.session.missing().empty());
  if (ImGui::Button("Automatic proposals")) {
    s.run("Proposing objects", [&s] {
      s.review_group = s.session.propose();
      s.after_command();
    });
  }
  s.probe("propose");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(s.px(110));
  ImGui::Combo("view", &s.panorama_channel, "colour\0range\0intensity\0normals\0");
  s.probe("panorama channel");
  ImGui::SameLine();
  // Enabled read-only too: grows are taken back there (commands are refused).
  if (ImGui::Button("Undo")) s.undo();
  s.probe("undo");
  ImGui::SameLine();
  if (ImGui::Button("Redo")) s.redo();
  s.probe("redo");
  ImGui::SameLine();
  ImGui::BeginDisabled(!s.session.has_grid());
  if (ImGui::Button("Clear lasso")) s.session.clear_constraints();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("Clear the panorama's lasso and barriers (Esc)");
  ImGui::EndDisabled();
}

}  // namespace

void toolbar_panel(WorkbenchState& s) {
  const float w = ImGui::GetIO().DisplaySize.x - s.px(kPanelWidth);
  place_window(s.px(kPanelWidth), 0, w, s.px(kToolbarHeight));
  ImGui::Begin("Tools", nullptr, kFixedWindow | ImGuiWindowFlags_NoTitleBar);
  tools_row(s);
  commands_row(s);
  ImGui::End();
}

}  // namespace scanbench::app::workbench

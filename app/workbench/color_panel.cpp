#include <optional>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

// The sliders; each one moved is recorded in s.touched.
void sliders(WorkbenchState& s) {
  s.touched[0] |= ImGui::SliderFloat("brightness", &s.color.brightness, -50.0f, 50.0f, "%.1f");
  s.probe_slider("brightness");
  s.touched[1] |= ImGui::SliderFloat("contrast", &s.color.contrast, 0.2f, 3.0f, "%.2f");
  s.probe_slider("contrast");
  s.touched[2] |= ImGui::SliderFloat("gamma", &s.color.gamma, 0.2f, 5.0f, "%.2f");
  s.probe_slider("gamma");
  s.touched[3] |= ImGui::SliderFloat("hue", &s.color.hue, -180.0f, 180.0f, "%.0f°");
  s.probe_slider("hue");
  s.touched[4] |= ImGui::SliderFloat("saturation", &s.color.saturation, 0.0f, 3.0f, "%.2f");
  s.probe_slider("saturation");
}

// What the moved sliders set; the rest the node goes on inheriting.
store::ColorEdit moved_sliders(const WorkbenchState& s) {
  store::ColorEdit set;
  if (s.touched[0]) set.brightness = s.color.brightness;
  if (s.touched[1]) set.contrast = s.color.contrast;
  if (s.touched[2]) set.gamma = s.color.gamma;
  if (s.touched[3]) set.hue_deg = s.color.hue;
  if (s.touched[4]) set.saturation = s.color.saturation;
  return set;
}

}  // namespace

void color_panel(WorkbenchState& s) {
  if (!ImGui::CollapsingHeader("Colour", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const auto p = s.primary();
  const std::optional<store::ObjectNode> n = p ? s.node(*p) : std::nullopt;
  ImGui::Text("%s", n ? n->name.c_str() : "select an object to edit its colours");
  // Present without a selection too (disabled), so the panel below keeps
  // its place.
  ImGui::BeginDisabled(!n);
  sliders(s);
  // Apply sets what was moved (and keeps what the node set before).
  if (ImGui::Button("Apply") && n) {
    const store::ColorEdit set = moved_sliders(s);
    s.run("Recolouring \"" + n->name + "\"", [&s, id = n->id, set] {
      if (!set.empty()) s.session.recolor(id, set, false);
      s.load_color_editor();
    });
  }
  s.probe("apply colour");
  ImGui::SameLine();
  if (ImGui::Button("Inherit") && n) {
    s.run("Recolouring \"" + n->name + "\"", [&s, id = n->id] {
      s.session.recolor(id, {}, true);
      s.load_color_editor();
    });
  }
  s.probe("inherit colour");
  ImGui::SameLine();
  // Clone: the other selected node is the source.
  const bool two = n && s.selected.size() == 2;
  ImGui::BeginDisabled(!two);
  if (ImGui::Button("Clone from other") && two) {
    const std::int64_t source =
        *s.selected.begin() == n->id ? *s.selected.rbegin() : *s.selected.begin();
    s.run("Cloning colours", [&s, source, id = n->id] {
      s.session.clone(source, id);
      s.load_color_editor();
    });
  }
  s.probe("clone colour");
  ImGui::EndDisabled();
  ImGui::EndDisabled();
}

}  // namespace scanbench::app::workbench

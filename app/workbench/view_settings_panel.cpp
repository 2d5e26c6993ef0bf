#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

void view_settings_panel(WorkbenchState& s) {
  // Closed at first: the sections below it stay in a 800-pixel window.
  if (!ImGui::CollapsingHeader("3D view")) return;
  render::RenderSettings& settings = s.settings;
  bool changed = false;
  int kernel = static_cast<int>(settings.kernel);
  changed |= ImGui::Combo("kernel", &kernel, "disk\0gaussian\0cosine\0");
  settings.kernel = static_cast<render::Kernel>(kernel);
  changed |= ImGui::SliderFloat("splat scale", &settings.splat_scale, 0.5f, 4.0f, "%.2f");
  bool blended = settings.mode == render::DrawMode::kBlended;
  changed |= ImGui::Checkbox("two-pass blending", &blended);
  settings.mode = blended ? render::DrawMode::kBlended : render::DrawMode::kSplats;
  // Moving frames keep to this time; a still view refines to every point.
  if (ImGui::SliderFloat("frame target (ms)", &s.frame_target_ms, 20.0f, 1000.0f, "%.0f")) {
    s.budget = render::FrameBudget(s.frame_target_ms);
    changed = true;
  }
  int color = static_cast<int>(settings.color);
  changed |= ImGui::Combo("colour", &color, "colour\0intensity\0height\0normal\0object\0");
  settings.color = static_cast<render::ColorMode>(color);
  changed |= ImGui::Checkbox("headlight", &settings.lighting);
  s.probe("headlight");
  ImGui::SameLine();
  changed |= ImGui::Checkbox("eye-dome lighting", &settings.eye_dome);
  s.probe("eye dome");
  int navigation = s.fly ? 1 : 0;
  ImGui::RadioButton("orbit", &navigation, 0);
  s.probe("orbit");
  ImGui::SameLine();
  ImGui::RadioButton("walk/fly (W A S D Q E)", &navigation, 1);
  s.probe("fly");
  s.fly = navigation == 1;
  ImGui::Text("speed %.1f m/s", s.navigation.speed_m_per_s());
  if (changed) s.view_dirty = true;
}

}  // namespace scanbench::app::workbench

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
  int budget = static_cast<int>(settings.culling.budget / 1000);
  changed |= ImGui::SliderInt("budget (k)", &budget, 50, 8000);
  settings.culling.budget = static_cast<std::size_t>(budget) * 1000;
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

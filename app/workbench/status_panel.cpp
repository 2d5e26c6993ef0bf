#include <cstdio>
#include <string>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

void status_panel(WorkbenchState& s) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  place_window(0, size.y - s.px(kStatusHeight), size.x, s.px(kStatusHeight));
  ImGui::Begin("Status", nullptr,
               kFixedWindow | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar);
  const render::LodFramePlan& plan = s.last_plan;
  // The device's time where it reports one, beside the wall time; the rate
  // once two frames have passed.
  const std::string gpu =
      s.last_gpu_ms >= 0.0 ? std::to_string(static_cast<int>(s.last_gpu_ms + 0.5)) + " ms device, "
                           : std::string();
  char rate[32] = "-";
  if (s.frame_seconds > 0.0) std::snprintf(rate, sizeof rate, "%.1f", 1.0 / s.frame_seconds);
  if (s.session.read_only()) {
    ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "READ-ONLY");
    ImGui::SameLine();
  }
  // How long the last command took, beside what it did.
  char took[48] = "";
  if (!s.command_status.empty() && s.command_status == s.session.status())
    std::snprintf(took, sizeof took, " (%.1f s)", s.command.seconds());
  ImGui::Text(
      "%s%s | selection %zu px | 3D %zu of %zu points in %zu nodes (left out: clip %zu, frustum "
      "%zu, budget %zu; %zu nodes loading) | draw %s%.0f ms wall | %s frames/s",
      s.session.status().empty() ? "ready" : s.session.status().c_str(), took,
      s.session.selected_pixels(), plan.submitted, plan.points, plan.draws.size(), plan.culled_clip,
      plan.culled_frustum, plan.stopped_by_budget, plan.wanted.size(), gpu.c_str(), s.last_draw_ms,
      rate);
  ImGui::End();
}

}  // namespace scanbench::app::workbench

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

void status_panel(WorkbenchState& s) {
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  place_window(0, size.y - kStatusHeight, size.x, kStatusHeight);
  ImGui::Begin("Status", nullptr,
               kFixedWindow | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar);
  const render::FramePlan& plan = s.last_plan;
  ImGui::Text(
      "%s | selection %zu px | 3D: %zu of %zu points drawn (frustum %zu, backface %zu, "
      "detail/budget %zu) in %.0f ms | %.1f frames/s",
      s.session.status().empty() ? "ready" : s.session.status().c_str(),
      s.session.selected_pixels(), plan.submitted, plan.points, plan.culled_frustum,
      plan.culled_backface, plan.culled_budget, s.last_draw_ms,
      s.frame_seconds > 0 ? 1.0 / s.frame_seconds : 0.0);
  ImGui::End();
}

}  // namespace scanbench::app::workbench

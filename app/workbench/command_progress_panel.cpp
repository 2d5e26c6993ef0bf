#include <cmath>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

// A command shorter than this shows no indicator (no flicker).
constexpr double kIndicatorAfterSeconds = 0.25;

}  // namespace

void command_progress_panel(const WorkbenchState& s) {
  const BackgroundCommand& command = s.command;
  const double seconds = command.seconds();
  if (seconds < kIndicatorAfterSeconds) return;
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImGui::GetBackgroundDrawList()->AddRectFilled(ImVec2(0, 0), size, IM_COL32(0, 0, 0, 110));
  const float box_w = s.px(420), box_h = s.px(78);
  place_window(0.5f * (size.x - box_w), 0.45f * (size.y - box_h), box_w, box_h);
  ImGui::Begin("##running", nullptr,
               kFixedWindow | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoInputs);
  ImGui::Text("%s ...", command.label().c_str());
  ImGui::TextDisabled("%.1f s; the window takes no input until it ends", seconds);
  // No fraction is known: a lit stretch sweeps to and fro, there and back
  // in 3.2 s.
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float bar_w = ImGui::GetContentRegionAvail().x, bar_h = s.px(8);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->AddRectFilled(at, ImVec2(at.x + bar_w, at.y + bar_h), IM_COL32(60, 64, 72, 255));
  const double phase = std::fmod(seconds / 1.6, 2.0);
  const float lit = 0.3f * bar_w;
  const float from = static_cast<float>(phase < 1.0 ? phase : 2.0 - phase) * (bar_w - lit);
  draw->AddRectFilled(ImVec2(at.x + from, at.y), ImVec2(at.x + from + lit, at.y + bar_h),
                      IM_COL32(90, 160, 240, 255));
  ImGui::Dummy(ImVec2(bar_w, bar_h));
  ImGui::End();
}

}  // namespace scanbench::app::workbench

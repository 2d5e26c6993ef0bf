#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

// The shown scan's pose: its scanner's position and heading in the world.
void pose_of_shown_scan(const WorkbenchState& s) {
  for (const store::StoredScanSummary& scan : s.session.scans()) {
    if (scan.id != s.session.scan_id()) continue;
    const Eigen::Isometry3d& pose = scan.summary.T_world_scan;
    const Eigen::Vector3d t = pose.translation();
    const Eigen::Vector3d x = pose.linear().col(0);
    const double heading = std::atan2(x.y(), x.x()) * 180.0 / std::numbers::pi;
    const double tilt =
        std::acos(std::clamp(pose.linear()(2, 2), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    ImGui::TextWrapped("pose: at %.3f, %.3f, %.3f m; heading %.2f°, tilt %.2f°", t.x(), t.y(),
                       t.z(), heading, tilt);
  }
}

}  // namespace

void scans_panel(WorkbenchState& s) {
  if (!ImGui::CollapsingHeader("Scans", ImGuiTreeNodeFlags_DefaultOpen)) return;
  // Opened after the list is drawn: opening a scan reloads the list.
  std::optional<std::int64_t> chosen;
  for (const store::StoredScanSummary& scan : s.session.scans()) {
    const bool current = scan.id == s.session.scan_id();
    const std::string label = std::to_string(scan.id) + "  " + scan.summary.name;
    if (ImGui::Selectable(label.c_str(), current) && !current) chosen = scan.id;
    s.probe("scan " + std::to_string(scan.id));
    if (ImGui::IsItemHovered()) {
      const Eigen::Vector3d t = scan.summary.T_world_scan.translation();
      if (scan.summary.scattered) {
        ImGui::SetTooltip("unstructured cloud of %zu points\norigin at %.3f %.3f %.3f m",
                          scan.summary.valid_points, t.x(), t.y(), t.z());
      } else {
        ImGui::SetTooltip("%d × %d, %zu valid points\nat %.3f %.3f %.3f m", scan.summary.rows,
                          scan.summary.columns, scan.summary.valid_points, t.x(), t.y(), t.z());
      }
    }
  }
  if (chosen && s.run("Opening scan " + std::to_string(*chosen),
                      [&s, id = *chosen] { s.session.open_scan(id); })) {
    s.zoom = 1.0f;
    s.pan = {0.0f, 0.0f};
  }
  pose_of_shown_scan(s);
  if (const auto report = s.session.project().latest_result("register")) {
    if (ImGui::TreeNode("Registration report")) {
      const nlohmann::json j = nlohmann::json::parse(*report, nullptr, false);
      ImGui::TextWrapped("%s", j.is_discarded() ? report->c_str() : j.dump(1).c_str());
      ImGui::TreePop();
    }
  }
}

}  // namespace scanbench::app::workbench

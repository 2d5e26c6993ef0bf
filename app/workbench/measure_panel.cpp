#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

constexpr int kMeasureKinds = 5;  // point, distance, height, angle, area (modeling::MeasureKind)

std::string describe(const modeling::Measurement& m) {
  return fmt::format("{}: {:.3f} {}", m.name, modeling::measured_value(m),
                     modeling::measured_unit(m.kind));
}

// The list, each with its value, its coordinates on hover, and a button
// that removes it.
void measurement_list(WorkbenchState& s) {
  const std::vector<modeling::Measurement> list = s.session.measurements();
  for (std::size_t k = 0; k < list.size(); ++k) {
    ImGui::TextUnformatted(describe(list[k]).c_str());
    if (ImGui::IsItemHovered()) {
      std::string points;
      for (const Eigen::Vector3d& p : list[k].points)
        points += fmt::format("{:.3f}, {:.3f}, {:.3f}\n", p.x(), p.y(), p.z());
      ImGui::SetTooltip("%s", points.c_str());
    }
    ImGui::SameLine();
    if (ImGui::SmallButton(("remove##m" + std::to_string(k)).c_str())) {
      std::vector<modeling::Measurement> rest = list;
      rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
      s.run("Removing " + list[k].name, [&s, rest, what = "removed " + list[k].name] {
        s.session.save_measurements(rest, what);
      });
    }
    s.probe("remove " + list[k].name);
  }
}

// The clipping box and the slice, in world coordinates.
void clip_settings(WorkbenchState& s) {
  ImGui::Checkbox("clip box", &s.clip_on);
  s.probe("clip box");
  ImGui::SameLine();
  ImGui::BeginDisabled(!s.primary());
  if (ImGui::Button("to selection")) s.clip_to_selection();
  s.probe("clip to selection");
  ImGui::EndDisabled();
  if (s.clip_on) {
    ImGui::DragScalarN("min", ImGuiDataType_Double, s.clip_min.data(), 3, 0.05f, nullptr, nullptr,
                       "%.2f");
    ImGui::DragScalarN("max", ImGuiDataType_Double, s.clip_max.data(), 3, 0.05f, nullptr, nullptr,
                       "%.2f");
  }
  if (ImGui::Checkbox("slice", &s.slice_on) && s.slice_on)
    s.slice_at = s.navigation.target()[s.slice_axis];
  s.probe("slice");
  if (s.slice_on) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(s.px(60));
    if (ImGui::Combo("across", &s.slice_axis, "x\0y\0z\0"))
      s.slice_at = s.navigation.target()[s.slice_axis];  // a coordinate of the new axis
    ImGui::DragScalar("at [m]", ImGuiDataType_Double, &s.slice_at, 0.05f, nullptr, nullptr, "%.2f");
    ImGui::SliderFloat("thickness [m]", &s.slice_thickness, 0.05f, 20.0f, "%.2f",
                       ImGuiSliderFlags_Logarithmic);
  }
}

}  // namespace

void measure_panel(WorkbenchState& s) {
  if (!ImGui::CollapsingHeader("Clip and measure", ImGuiTreeNodeFlags_DefaultOpen)) return;
  clip_settings(s);
  ImGui::Separator();
  if (ImGui::Checkbox("pick points (M)", &s.measuring)) s.picks.clear();
  s.probe("measure");
  ImGui::SameLine();
  // The kinds, each probed while the list is open ("measure kind area").
  const auto name_of = [](int kind) {
    return std::string(modeling::measure_kind_name(static_cast<modeling::MeasureKind>(kind)));
  };
  ImGui::SetNextItemWidth(s.px(90));
  const bool open = ImGui::BeginCombo("##kind", name_of(s.measure_kind).c_str());
  s.probe("measure kind");
  if (open) {
    for (int kind = 0; kind < kMeasureKinds; ++kind) {
      if (ImGui::Selectable(name_of(kind).c_str(), kind == s.measure_kind) &&
          kind != s.measure_kind) {
        s.measure_kind = kind;
        s.picks.clear();
      }
      s.probe("measure kind " + name_of(kind));
    }
    ImGui::EndCombo();
  }
  const auto kind = static_cast<modeling::MeasureKind>(s.measure_kind);
  if (s.measuring) {
    ImGui::Text("%zu of %s%zu points picked", s.picks.size(),
                modeling::takes_more_points(kind) ? "at least " : "",
                modeling::points_needed(kind));
    if (modeling::takes_more_points(kind)) {
      ImGui::SameLine();
      ImGui::BeginDisabled(s.picks.size() < modeling::points_needed(kind));
      if (ImGui::Button("Finish (Enter)")) s.finish_measurement();
      s.probe("finish measurement");
      ImGui::EndDisabled();
    }
  }
  measurement_list(s);
  if (s.csv_path[0] == '\0') {
    std::filesystem::path csv = s.session.project().path();
    csv.replace_extension();
    const std::string text = csv.string() + "_measurements.csv";
    text.copy(s.csv_path.data(), s.csv_path.size() - 1);
  }
  ImGui::SetNextItemWidth(s.px(220));
  ImGui::InputText("##csv", s.csv_path.data(), s.csv_path.size());
  ImGui::SameLine();
  ImGui::BeginDisabled(s.session.measurements().empty());
  if (ImGui::Button("Export CSV")) {
    const std::filesystem::path file = s.csv_path.data();
    std::error_code error;
    if (std::filesystem::exists(file, error)) {
      // An earlier export is replaced only once confirmed.
      s.question =
          Question{"Replace the file?",
                   file.string() + " exists. Exporting replaces it with the measurements listed.",
                   "Replace", [&s, file] { s.session.export_measurements(file); }};
    } else {
      s.run("Exporting the measurements", [&s, file] { s.session.export_measurements(file); });
    }
  }
  s.probe("export csv");
  ImGui::EndDisabled();
}

void measurement_overlay(WorkbenchState& s, ImDrawList* draw,
                         const std::function<std::optional<ImVec2>(const Eigen::Vector3d&)>& at,
                         float longest_line) {
  const float thick = s.px(2), dot = s.px(4);
  // The points that project, and the lines between neighbours that both do
  // and are no longer than `longest_line` (a panorama's seam).
  const auto path = [&](const std::vector<Eigen::Vector3d>& points, bool closed, ImU32 colour) {
    std::vector<std::optional<ImVec2>> screen;
    for (const Eigen::Vector3d& p : points) screen.push_back(at(p));
    const std::size_t n = screen.size();
    const std::size_t lines = closed && n > 2 ? n : std::max<std::size_t>(n, 1) - 1;
    for (std::size_t k = 0; k < lines; ++k) {
      const std::optional<ImVec2>& a = screen[k];
      const std::optional<ImVec2>& b = screen[(k + 1) % n];
      if (a && b && std::hypot(b->x - a->x, b->y - a->y) <= longest_line)
        draw->AddLine(*a, *b, colour, thick);
    }
    std::optional<ImVec2> last;
    for (const std::optional<ImVec2>& p : screen) {
      if (!p) continue;
      draw->AddCircleFilled(*p, dot, colour);
      last = p;
    }
    return last;
  };
  for (const modeling::Measurement& m : s.session.measurements()) {
    const bool area = m.kind == modeling::MeasureKind::kArea;
    if (const std::optional<ImVec2> label = path(m.points, area, IM_COL32(255, 120, 255, 255))) {
      draw->AddText(ImVec2(label->x + s.px(6), label->y - s.px(16)), IM_COL32(255, 255, 255, 255),
                    describe(m).c_str());
    }
  }
  path(s.picks, false, IM_COL32(255, 230, 40, 255));
}

}  // namespace scanbench::app::workbench

#include "app/workbench/workbench_state.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace scanbench::app::workbench {

WorkbenchState::WorkbenchState(const WorkbenchOptions& options, render::WindowDevice& window)
    : options(options), window(window), session(options.project) {
  settings.culling.budget = 1'500'000;
}

void WorkbenchState::layout(int width, int height) {
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  const float views_height = h - kToolbarHeight - kStatusHeight;
  panorama = {kPanelWidth, kToolbarHeight, w - kPanelWidth, std::round(0.45f * views_height)};
  view3d = {kPanelWidth, panorama.y + panorama.h, w - kPanelWidth, views_height - panorama.h};
}

float WorkbenchState::panorama_scale() const {
  return panorama.w / static_cast<float>(std::max(session.scan().columns, 1)) * zoom;
}

// Pixel (col, row) covers [col − ½, col + ½) × [row − ½, row + ½) of image
// coordinates, and col × scale to (col + 1) × scale of the view.
std::array<double, 2> WorkbenchState::panorama_pixel(double x, double y) const {
  const float scale = panorama_scale();
  return {(x - panorama.x - pan[0]) / scale - 0.5, (y - panorama.y - pan[1]) / scale - 0.5};
}

ImVec2 WorkbenchState::panorama_screen(const Eigen::Vector2d& pixel) const {
  const float scale = panorama_scale();
  return ImVec2(panorama.x + pan[0] + static_cast<float>(pixel.x() + 0.5) * scale,
                panorama.y + pan[1] + static_cast<float>(pixel.y() + 0.5) * scale);
}

void WorkbenchState::probe(const std::string& widget) {
  const ImVec2 low = ImGui::GetItemRectMin(), high = ImGui::GetItemRectMax();
  probes[widget] = {0.5f * (low.x + high.x), 0.5f * (low.y + high.y)};
}

void WorkbenchState::probe_slider(const std::string& widget) {
  const ImVec2 low = ImGui::GetItemRectMin(), high = ImGui::GetItemRectMax();
  probes[widget] = {low.x + 0.5f * ImGui::CalcItemWidth(), 0.5f * (low.y + high.y)};
}

std::optional<std::int64_t> WorkbenchState::primary() const {
  if (selected.empty()) return std::nullopt;
  return primary_id;
}

std::optional<store::ObjectNode> WorkbenchState::node(std::int64_t id) const {
  for (const store::ObjectNode& n : session.nodes())
    if (n.id == id) return n;
  return std::nullopt;
}

void WorkbenchState::select_only(std::int64_t id) {
  selected = {id};
  primary_id = id;
  load_color_editor();
}

void WorkbenchState::load_color_editor() {
  color = {};
  touched = {};
  const auto p = primary();
  if (!p || !node(*p)) return;
  const store::ColorEdit own = node(*p)->color;
  color.brightness = static_cast<float>(own.brightness.value_or(0.0));
  color.contrast = static_cast<float>(own.contrast.value_or(1.0));
  color.gamma = static_cast<float>(own.gamma.value_or(1.0));
  color.hue = static_cast<float>(own.hue_deg.value_or(0.0));
  color.saturation = static_cast<float>(own.saturation.value_or(1.0));
}

void WorkbenchState::after_command() {
  if (selected.size() == 1 && !node(*selected.begin())) selected.clear();
  load_color_editor();
}

void WorkbenchState::commit() {
  std::optional<std::int64_t> parent;
  if (const auto p = primary(); p && node(*p)) {
    const store::ObjectNode n = *node(*p);
    parent = n.kind == store::NodeKind::kGroup ? std::optional(n.id) : n.parent;
  }
  if (session.commit(name_text(), parent)) {
    const std::int64_t made = session.nodes().empty() ? 0 : session.nodes().back().id;
    select_only(made);
  }
}

void WorkbenchState::group() {
  const std::vector<std::int64_t> children(selected.begin(), selected.end());
  if (session.group(name_text(), children)) select_only(session.nodes().back().id);
}

void WorkbenchState::frame_whole_model() {
  const render::RenderModel& model = session.render_model();
  const std::size_t n = model.points.size();
  if (n == 0) return;
  const std::size_t step = std::max<std::size_t>(1, n / 20000);
  std::array<std::vector<float>, 3> axes;
  for (std::size_t k = 0; k < n; k += step)
    for (int a = 0; a < 3; ++a)
      axes[static_cast<std::size_t>(a)].push_back(model.points.position[k][a]);
  Eigen::AlignedBox3d box;
  for (int a = 0; a < 3; ++a) {
    std::vector<float>& v = axes[static_cast<std::size_t>(a)];
    std::sort(v.begin(), v.end());
    box.min()[a] = v[v.size() / 50] + model.origin[a];
    box.max()[a] = v[v.size() - 1 - v.size() / 50] + model.origin[a];
  }
  navigation.frame(box);
  view_dirty = true;
}

void WorkbenchState::frame_selection() {
  const auto p = primary();
  const std::optional<store::ObjectNode> n = p ? node(*p) : std::nullopt;
  if (n && n->bbox_world) {
    navigation.frame(*n->bbox_world);
    view_dirty = true;
  } else {
    frame_whole_model();
  }
}

}  // namespace scanbench::app::workbench

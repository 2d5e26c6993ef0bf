#include <epoxy/gl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

// Uploads the panorama when the project, the channel, the scan or the
// selected node changed.
void refresh_texture(WorkbenchState& s) {
  const std::int64_t highlight = s.primary().value_or(0);
  const std::array<std::int64_t, 4> key = {s.session.revision(), s.panorama_channel,
                                           s.session.scan_id(), highlight};
  if (key == s.panorama_key) return;
  const render::Picture picture =
      s.session.panorama(static_cast<render::PanoramaChannel>(s.panorama_channel), highlight);
  glBindTexture(GL_TEXTURE_2D, s.panorama_texture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, picture.width, picture.height, 0, GL_RGBA,
               GL_UNSIGNED_BYTE, picture.rgba.data());
  s.panorama_key = key;
}

// A lasso or barrier drawn over the panorama, its vertices marked.
void polyline(const WorkbenchState& s, ImDrawList* draw, const segmentation::Polyline& line,
              ImU32 colour, bool closed) {
  std::vector<ImVec2> points;
  for (const Eigen::Vector2d& v : line) points.push_back(s.panorama_screen(v));
  if (points.empty()) return;
  draw->AddPolyline(points.data(), static_cast<int>(points.size()), colour,
                    closed ? ImDrawFlags_Closed : 0, s.px(2));
  for (const ImVec2& p : points) draw->AddCircleFilled(p, s.px(3), colour);
}

}  // namespace

void panorama_view(WorkbenchState& s) {
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  const ImVec2 low(s.panorama.x, s.panorama.y),
      high(s.panorama.x + s.panorama.w, s.panorama.y + s.panorama.h);
  draw->PushClipRect(low, high, true);
  draw->AddRectFilled(low, high, IM_COL32(20, 20, 24, 255));
  const std::string missing = s.session.missing();
  if (!s.session.has_grid()) {
    draw->AddText(ImVec2(low.x + s.px(12), low.y + s.px(10)), IM_COL32(255, 200, 120, 255),
                  missing.c_str());
    draw->PopClipRect();
    return;
  }
  refresh_texture(s);
  const acquisition::Scan& scan = s.session.scan();
  draw->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(s.panorama_texture)),
                 s.panorama_screen({-0.5, -0.5}),
                 s.panorama_screen({scan.columns - 0.5, scan.rows - 0.5}));
  polyline(s, draw, s.session.lasso(), IM_COL32(80, 220, 255, 255), s.session.lasso_closed());
  for (const segmentation::Polyline& b : s.session.barriers())
    polyline(s, draw, b, IM_COL32(255, 70, 70, 255), false);
  // Measurements where this scan sees them; a line across the seam of a
  // full circle (longer than half the picture) is left out.
  measurement_overlay(
      s, draw,
      [&s](const Eigen::Vector3d& p) -> std::optional<ImVec2> {
        const std::optional<Eigen::Vector2d> image = s.session.image_point(p);
        if (!image) return std::nullopt;
        return s.panorama_screen(*image);
      },
      0.5f * s.panorama_scale() * static_cast<float>(scan.columns));
  if (!missing.empty()) {
    const ImVec2 at(low.x + s.px(12), high.y - s.px(24));
    const ImVec2 size = ImGui::CalcTextSize(missing.c_str());
    const float mx = s.px(4), my = s.px(2);
    draw->AddRectFilled(ImVec2(at.x - mx, at.y - my),
                        ImVec2(at.x + size.x + mx, at.y + size.y + my), IM_COL32(0, 0, 0, 200));
    draw->AddText(at, IM_COL32(255, 200, 120, 255), missing.c_str());
  }
  draw->PopClipRect();
}

}  // namespace scanbench::app::workbench

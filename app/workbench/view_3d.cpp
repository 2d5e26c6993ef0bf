#include <cstdint>
#include <limits>
#include <memory>
#include <string>

#include "app/workbench/panels.hpp"
#include "render/render_view.hpp"

namespace scanbench::app::workbench {

namespace {

// Draws the model into the renderer's picture when the view or the model
// changed.
void redraw(WorkbenchState& s, int width, int height) {
  const render::RenderModel& model = s.session.render_model();  // built anew when stale
  if (!s.renderer || s.renderer_generation != s.session.render_model_generation()) {
    s.renderer.reset();
    s.renderer = std::make_unique<render::SplatRenderer>(model);
    s.renderer_generation = s.session.render_model_generation();
    s.view_dirty = true;
  }
  s.apply_clipping();
  if (!s.view_dirty) return;
  const render::RenderView view =
      render::make_render_view(s.navigation.camera(width, height), s.session.render_model().origin);
  const render::FrameResult frame = s.renderer->draw(view, s.settings);
  s.last_plan = frame.plan;
  s.last_draw_ms = frame.frame_ms;  // the renderer gives ImGui its GL state back
  s.last_gpu_ms = frame.gpu_ms;
  s.view_dirty = false;
}

}  // namespace

void view_3d(WorkbenchState& s) {
  const int w = static_cast<int>(s.view3d.w), h = static_cast<int>(s.view3d.h);
  if (w <= 0 || h <= 0) return;
  redraw(s, w, h);
  const render::SplatRenderer::PictureTexture picture = s.renderer->picture_texture();
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  const Rect& r = s.view3d;
  // The texture's bottom row first: flipped.
  draw->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(picture.texture)),
                 ImVec2(r.x, r.y), ImVec2(r.x + r.w, r.y + r.h),
                 ImVec2(picture.uv[0], picture.uv[3]), ImVec2(picture.uv[2], picture.uv[1]));
  draw->AddText(ImVec2(r.x + s.px(8), r.y + s.px(6)), IM_COL32(255, 255, 255, 200),
                s.fly ? "walk/fly: W A S D Q E, drag to look"
                      : "orbit: drag to turn, right-drag to pan, wheel to zoom");
  draw->PushClipRect(ImVec2(r.x, r.y), ImVec2(r.x + r.w, r.y + r.h), true);
  measurement_overlay(
      s, draw, [&s](const Eigen::Vector3d& p) { return s.screen_of(p); },
      std::numeric_limits<float>::infinity());
  draw->PopClipRect();
  const std::string& problem = s.session.render_model_problem();
  if (!problem.empty()) {
    const std::string text = "nothing to draw: " + problem;
    draw->AddText(ImVec2(r.x + s.px(8), r.y + s.px(26)), IM_COL32(255, 200, 120, 255),
                  text.c_str());
  }
}

}  // namespace scanbench::app::workbench

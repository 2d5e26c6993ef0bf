#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/workbench/panels.hpp"
#include "render/render_view.hpp"

namespace scanbench::app::workbench {

namespace {

// The renderer follows the session's store: an update in place of the one
// it draws keeps the nodes it did not rewrite in both caches; another
// store gets a renderer of its own.
void follow_the_store(WorkbenchState& s) {
  Session& session = s.session;
  if (s.renderer_generation == session.store_generation()) return;
  const bool updated = s.renderer && s.renderer_generation + 1 == session.store_generation() &&
                       session.rewritten().has_value();
  s.renderer_generation = session.store_generation();
  s.shown_revision = -1;
  s.shown_objects.clear();
  s.view_dirty = true;
  if (updated) {
    s.renderer->follow_update(*session.rewritten());
    ++s.renderer_follows;
    return;
  }
  s.renderer.reset();
  if (!session.store().empty()) {
    s.renderer =
        std::make_unique<render::LodRenderer>(session.store(), render::LodRendererLimits{});
    ++s.renderers_opened;
  }
}

// The objects' visibility and colours, and the scans' corrections, into
// the renderer when a command changed them: the next frame shows them.
void follow_the_objects(WorkbenchState& s) {
  Session& session = s.session;
  if (s.shown_revision == session.revision()) return;
  s.shown_revision = session.revision();
  decltype(s.shown_objects) objects;
  for (const store::ObjectNode& n : session.nodes())
    objects.emplace_back(n.id, n.parent, n.hidden, n.color);
  const std::int64_t corrections =
      session.project().changed_at(store::ProjectData::kColorCorrections);
  if (objects == s.shown_objects && corrections == s.shown_corrections) return;
  s.renderer->show_project_state(session.project());
  s.shown_objects = std::move(objects);
  s.shown_corrections = corrections;
  s.view_dirty = true;
}

// Draws a frame into the renderer's picture when the view changed (a
// moving frame, within the budget) or the last one is not complete yet (a
// refining frame, without one).
void redraw(WorkbenchState& s, int width, int height) {
  follow_the_store(s);
  if (!s.renderer) return;
  follow_the_objects(s);
  s.apply_clipping();
  const bool moving = s.view_dirty;
  if (!moving && s.last_plan.stopped_by_budget == 0 && !s.renderer->has_more_to_draw()) return;
  render::RenderSettings settings = s.settings;
  settings.culling.budget = s.budget.next(moving);
  // Refining while nodes are read, a preview within the moving frames'
  // budget: the whole picture is drawn once, when they are in.
  settings.culling.preview_budget = s.budget.next(true);
  // Moving, the frame may be drawn smaller (render/frame_budget.hpp).
  const render::RenderView view = render::make_render_view(
      render::at_scale(s.navigation.camera(width, height), s.budget.scale(moving)),
      s.renderer->header().origin);
  // Refining, each frame draws the whole picture again: it waits a little
  // for the nodes being read, so that fewer frames draw more each.
  const render::LodFrameResult frame = s.renderer->draw(
      view, settings, moving ? std::chrono::milliseconds(0) : std::chrono::milliseconds(250));
  if (moving) {
    s.budget.record(frame.frame_ms, frame.plan.submitted);
    ++s.moving_frames;
    if (settings.culling.budget == 0 || frame.plan.submitted > settings.culling.budget)
      ++s.frames_over_budget;
    if (s.moving_frame_ms.size() == WorkbenchState::kMovingFramesKept)
      s.moving_frame_ms.erase(s.moving_frame_ms.begin());
    s.moving_frame_ms.push_back(frame.frame_ms);
  }
  s.last_plan = frame.plan;
  s.last_draw_ms = frame.frame_ms;  // the renderer gives ImGui its GL state back
  s.last_gpu_ms = frame.gpu_ms;
  s.view_dirty = false;
}

// The 3D selection: a sample of its points marked, while the selection is
// the one they show, and the lasso or box being drawn.
void selection_overlay(WorkbenchState& s, ImDrawList* draw) {
  const ImU32 mark = IM_COL32(255, 230, 40, 220);
  if (s.marks_revision == s.session.revision() || s.drag == Drag::kBrush3d) {
    const Eigen::Vector3d origin = s.model_origin();
    const float half = std::max(1.0f, s.px(1.5f));
    for (const Eigen::Vector3f& p : s.selection_marks) {
      if (const std::optional<ImVec2> at = s.screen_of(origin + p.cast<double>()))
        draw->AddRectFilled(ImVec2(at->x - half, at->y - half), ImVec2(at->x + half, at->y + half),
                            mark);
    }
  }
  if (s.drag == Drag::kLasso3d && !s.lasso_3d.empty()) {
    std::vector<ImVec2> line;
    for (const Eigen::Vector2f& p : s.lasso_3d_polygon())
      line.emplace_back(s.view3d.x + p.x(), s.view3d.y + p.y());
    draw->AddPolyline(line.data(), static_cast<int>(line.size()), mark, ImDrawFlags_Closed,
                      s.px(1.5f));
  }
}

}  // namespace

void view_3d(WorkbenchState& s) {
  const int w = static_cast<int>(s.view3d.w), h = static_cast<int>(s.view3d.h);
  if (w <= 0 || h <= 0) return;
  redraw(s, w, h);
  ImDrawList* draw = ImGui::GetBackgroundDrawList();
  const Rect& r = s.view3d;
  if (s.renderer) {  // redraw() drew a first frame
    const render::PictureTexture picture = s.renderer->picture_texture();
    // The texture's bottom row first: flipped.
    draw->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(picture.texture)),
                   ImVec2(r.x, r.y), ImVec2(r.x + r.w, r.y + r.h),
                   ImVec2(picture.uv[0], picture.uv[3]), ImVec2(picture.uv[2], picture.uv[1]));
  }
  draw->AddText(ImVec2(r.x + s.px(8), r.y + s.px(6)), IM_COL32(255, 255, 255, 200),
                s.fly ? "walk/fly: W A S D Q E, drag to look"
                : s.session.tool == Tool::kLasso
                    ? "lasso: drag to select (Shift: a box), middle-drag to turn, right-drag to pan"
                : s.session.tool == Tool::kBrush
                    ? "brush: drag over surfaces to select, middle-drag to turn, right-drag to pan"
                    : "orbit: drag to turn, right-drag to pan, wheel to zoom");
  draw->PushClipRect(ImVec2(r.x, r.y), ImVec2(r.x + r.w, r.y + r.h), true);
  selection_overlay(s, draw);
  measurement_overlay(
      s, draw, [&s](const Eigen::Vector3d& p) { return s.screen_of(p); },
      std::numeric_limits<float>::infinity());
  draw->PopClipRect();
  const std::string& problem = s.session.view_problem();
  if (!problem.empty() || !s.renderer) {
    const std::string text = problem.empty() ? std::string("no level-of-detail store yet")
                                             : "nothing to draw: " + problem;
    draw->AddText(ImVec2(r.x + s.px(8), r.y + s.px(26)), IM_COL32(255, 200, 120, 255),
                  text.c_str());
  }
}

}  // namespace scanbench::app::workbench

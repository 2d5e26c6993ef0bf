#include "app/workbench/workbench_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "render/lasso.hpp"
#include "render/pick.hpp"
#include "segmentation/pixel_set.hpp"

namespace scanbench::app::workbench {

WorkbenchState::WorkbenchState(const WorkbenchOptions& options, render::WindowDevice& window)
    : options(options),
      window(window),
      session(options.project, options.read_only || Session::cannot_write(options.project)) {
  // A store to build first: in the background, the window showing it.
  if (!session.store_current())
    command.ask("Building the 3D view (level of detail)", [this] { session.prepare_views(); });
  // Proposals left in their group by an earlier session are still to review.
  const std::string proposals = modeling::ProposeSettings{}.group_name;
  for (const store::ObjectNode& n : session.nodes()) {
    if (n.kind == store::NodeKind::kGroup && n.name == proposals) review_group = n.id;
  }
}

void WorkbenchState::layout(int width, int height) {
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  const float ratio = std::min(w / 1280.0f, h / 800.0f);
  ui_scale = std::clamp(std::floor(4.0f * ratio) / 4.0f, 1.0f, 3.0f);
  const float left = px(kPanelWidth), top = px(kToolbarHeight);
  const float views_height = h - top - px(kStatusHeight);
  panorama = {left, top, w - left, std::round(0.45f * views_height)};
  view3d = {left, panorama.y + panorama.h, w - left, views_height - panorama.h};
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

std::set<std::int64_t> WorkbenchState::subtree(std::int64_t id) const {
  std::set<std::int64_t> inside = {id};
  for (bool grew = true; grew;) {
    grew = false;
    for (const store::ObjectNode& m : session.nodes()) {
      if (m.parent && inside.count(*m.parent) && inside.insert(m.id).second) grew = true;
    }
  }
  return inside;
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

bool WorkbenchState::run(std::string label, std::function<void()> work) {
  return command.ask(std::move(label), [this, work = std::move(work)] {
    work();
    session.prepare_views();
  });
}

void WorkbenchState::undo() {
  run("Undoing", [this] {
    const std::optional<store::CommandRecord> stage = session.undo();
    after_command();
    if (!stage) return;
    const std::int64_t id = stage->id;
    const std::string name = stage->name;
    question = Question{
        "Undo a batch stage?",
        "The newest command is \"" + name + "\" (command " + std::to_string(id) + ", " +
            stage->created_at +
            "), a batch stage run over whole scans, not an edit made here.\nUndoing it takes "
            "back its work on every scan; Ctrl+Y or `scanbench redo` brings it back.",
        "Undo " + name, [this, id] {
          session.undo(true, id);
          after_command();
          view_dirty = true;
        }};
  });
}

void WorkbenchState::redo() {
  run("Redoing", [this] {
    session.redo();
    after_command();
    view_dirty = true;
  });
}

void WorkbenchState::remove_selected() {
  const auto p = primary();
  const std::optional<store::ObjectNode> n = p ? node(*p) : std::nullopt;
  if (!n) return;
  const auto remove = [this, id = n->id] {
    session.remove(id);
    selected.clear();
    after_command();
  };
  const std::size_t descendants = subtree(n->id).size() - 1;
  if (n->kind != store::NodeKind::kGroup || descendants == 0) {
    run("Deleting \"" + n->name + "\"", remove);
    return;
  }
  question = Question{"Delete a group?",
                      "\"" + n->name + "\" holds " + std::to_string(descendants) +
                          " node(s). Deleting it deletes them too: their points return to the "
                          "pool to be segmented again. Ctrl+Z brings them back.",
                      "Delete \"" + n->name + "\" and its " + std::to_string(descendants), remove};
}

void WorkbenchState::commit() {
  std::optional<std::int64_t> parent;
  if (const auto p = primary(); p && node(*p)) {
    const store::ObjectNode n = *node(*p);
    parent = n.kind == store::NodeKind::kGroup ? std::optional(n.id) : n.parent;
  }
  const std::string name = name_text();
  run("Committing \"" + name + "\"", [this, name, parent] {
    if (session.commit(name, parent))
      select_only(session.nodes().empty() ? 0 : session.nodes().back().id);
  });
}

void WorkbenchState::group() {
  const std::vector<std::int64_t> children(selected.begin(), selected.end());
  const std::string name = name_text();
  run("Grouping as \"" + name + "\"", [this, name, children] {
    if (session.group(name, children)) select_only(session.nodes().back().id);
  });
}

void WorkbenchState::frame_whole_model() {
  if (!renderer) return;
  const std::vector<render::LodSample> sample = renderer->sample(20000);
  if (sample.empty()) return;
  std::array<std::vector<float>, 3> axes;
  for (const render::LodSample& p : sample)
    for (int a = 0; a < 3; ++a) axes[static_cast<std::size_t>(a)].push_back(p.position[a]);
  const Eigen::Vector3d origin = model_origin();
  Eigen::AlignedBox3d box;
  for (int a = 0; a < 3; ++a) {
    std::vector<float>& v = axes[static_cast<std::size_t>(a)];
    std::sort(v.begin(), v.end());
    box.min()[a] = v[v.size() / 50] + origin[a];
    box.max()[a] = v[v.size() - 1 - v.size() / 50] + origin[a];
  }
  navigation.frame(box);
  view_dirty = true;
}

void WorkbenchState::frame_selection() {
  const auto p = primary();
  const std::optional<store::ObjectNode> n = p ? node(*p) : std::nullopt;
  if (!n || !n->bbox_world || !renderer) {
    frame_whole_model();
    return;
  }
  // The side the node's points were seen from: their normals point towards
  // their scanners, so their sum points out of its visible side.
  const std::set<std::int64_t> inside = subtree(n->id);
  Eigen::Vector3d facing = Eigen::Vector3d::Zero();
  for (const render::LodSample& point : renderer->sample(200000)) {
    if (point.object != 0 && inside.count(point.object)) facing += point.normal.cast<double>();
  }
  navigation.frame(*n->bbox_world, facing);
  view_dirty = true;
}

void WorkbenchState::clip_to_selection() {
  const auto p = primary();
  const std::optional<store::ObjectNode> n = p ? node(*p) : std::nullopt;
  if (!n || !n->bbox_world) return;
  const Eigen::Vector3d margin = 0.05 * n->bbox_world->sizes();
  for (int a = 0; a < 3; ++a) {
    clip_min[static_cast<std::size_t>(a)] = n->bbox_world->min()[a] - margin[a];
    clip_max[static_cast<std::size_t>(a)] = n->bbox_world->max()[a] + margin[a];
  }
  clip_on = true;
  view_dirty = true;
}

bool WorkbenchState::view_settled() const {
  if (!renderer) return renderer_generation == session.store_generation();
  return !view_dirty && last_plan.wanted.empty() && last_plan.stopped_by_budget == 0;
}

Eigen::Vector3d WorkbenchState::model_origin() const {
  return renderer ? renderer->header().origin : Eigen::Vector3d::Zero();
}

void WorkbenchState::apply_clipping() {
  const Eigen::Vector3d origin = model_origin();
  render::Clipping clipping;
  if (clip_on) {
    // Corners dragged past each other still make a box.
    const Eigen::Vector3d a(clip_min[0], clip_min[1], clip_min[2]);
    const Eigen::Vector3d b(clip_max[0], clip_max[1], clip_max[2]);
    const Eigen::Vector3d low = a.cwiseMin(b), high = a.cwiseMax(b);
    clipping.box = Eigen::AlignedBox3f((low - origin).cast<float>(), (high - origin).cast<float>());
  }
  if (slice_on) {
    clipping.section_normal = Eigen::Vector3f::Unit(slice_axis);
    clipping.section_offset = static_cast<float>(slice_at - origin[slice_axis]);
    clipping.section_half_width = 0.5f * std::max(slice_thickness, 0.001f);
  }
  render::Clipping& current = settings.culling.clipping;
  const bool same = current.box.min() == clipping.box.min() &&
                    current.box.max() == clipping.box.max() &&
                    current.section_normal == clipping.section_normal &&
                    current.section_offset == clipping.section_offset &&
                    current.section_half_width == clipping.section_half_width;
  if (same) return;
  current = clipping;
  view_dirty = true;
}

std::optional<render::LodPick> WorkbenchState::point_under(double x, double y) {
  const int w = static_cast<int>(view3d.w), h = static_cast<int>(view3d.h);
  if (!renderer || w <= 0 || h <= 0) return std::nullopt;
  const render::RenderView view = render::make_render_view(navigation.camera(w, h), model_origin());
  return renderer->pick(view.eye, render::pixel_ray(view, x - view3d.x, y - view3d.y), settings);
}

void WorkbenchState::select_in_3d(double x, double y, bool toggle) {
  const std::optional<render::LodPick> pick = point_under(x, y);
  const std::int64_t id = pick ? pick->object : 0;
  if (toggle) {
    if (id == 0) return;
    if (!selected.erase(id)) selected.insert(id);
    primary_id = id;
    load_color_editor();
  } else if (id != 0) {
    select_only(id);
  } else {
    selected.clear();
    load_color_editor();
  }
}

namespace {

// At most this many of a 3D selection's points are marked over the view.
constexpr std::size_t kSelectionMarks = 20000;

}  // namespace

void WorkbenchState::start_lasso_3d(double x, double y, bool box) {
  lasso_3d = {Eigen::Vector2f(static_cast<float>(x), static_cast<float>(y))};
  box_3d = box;
}

void WorkbenchState::extend_lasso_3d(double x, double y) {
  const Eigen::Vector2f at(static_cast<float>(x), static_cast<float>(y));
  if (box_3d) {
    lasso_3d.resize(1);
    lasso_3d.push_back(at);
  } else if (lasso_3d.empty() || (at - lasso_3d.back()).norm() >= 2.0f) {
    lasso_3d.push_back(at);
  }
}

std::vector<Eigen::Vector2f> WorkbenchState::lasso_3d_polygon() const {
  const Eigen::Vector2f corner(view3d.x, view3d.y);
  std::vector<Eigen::Vector2f> polygon;
  if (box_3d && lasso_3d.size() == 2) {
    const Eigen::Vector2f a = lasso_3d[0] - corner, b = lasso_3d[1] - corner;
    polygon = {a, {b.x(), a.y()}, b, {a.x(), b.y()}};
  } else {
    for (const Eigen::Vector2f& p : lasso_3d) polygon.push_back(p - corner);
  }
  return polygon;
}

void WorkbenchState::finish_lasso_3d() {
  const std::vector<Eigen::Vector2f> polygon = lasso_3d_polygon();
  lasso_3d.clear();
  const int w = static_cast<int>(view3d.w), h = static_cast<int>(view3d.h);
  if (!renderer || w <= 0 || h <= 0) return;
  const render::Lasso lasso(polygon);
  if (lasso.empty()) return;  // a click, not a lasso
  const render::RenderView view = render::make_render_view(navigation.camera(w, h), model_origin());
  const render::LodSelection taken =
      renderer->select(view, lasso, settings,
                       {.depth_m = select_through ? render::kEveryDepth : select_depth_m,
                        .sample = kSelectionMarks});
  session.select_pixels(taken.pixels, box_3d ? "box" : "lasso");
  selection_marks = taken.sample;
  marks_revision = session.revision();
}

void WorkbenchState::brush_at(double x, double y) {
  const std::optional<render::LodPick> pick = point_under(x, y);
  if (!pick) return;
  const render::LodSelection dab = renderer->select_sphere(pick->position, brush_radius_m, settings,
                                                           {.sample = kSelectionMarks / 50});
  for (const auto& [scan, pixels] : dab.pixels) {
    std::vector<std::uint32_t>& stroke = brushed[scan];
    stroke = segmentation::unite(stroke, pixels);
  }
  if (selection_marks.size() < kSelectionMarks)
    selection_marks.insert(selection_marks.end(), dab.sample.begin(), dab.sample.end());
  marks_revision = session.revision();
}

void WorkbenchState::finish_brush() {
  std::map<std::int64_t, std::vector<std::uint32_t>> stroke;
  stroke.swap(brushed);
  if (stroke.empty()) return;
  std::vector<Eigen::Vector3f> marks = std::move(selection_marks);
  session.select_pixels(stroke, "brush");
  selection_marks = std::move(marks);
  marks_revision = session.revision();
}

void WorkbenchState::pick_at(double x, double y) {
  const std::optional<render::LodPick> pick = point_under(x, y);
  if (pick) add_pick(model_origin() + pick->position.cast<double>());
}

void WorkbenchState::pick_in_panorama(double x, double y) {
  const segmentation::GridPixel pixel = segmentation::nearest_pixel(Eigen::Vector2d(x, y));
  if (const std::optional<Eigen::Vector3d> p = session.world_point(pixel.row, pixel.col))
    add_pick(*p);
}

void WorkbenchState::add_pick(const Eigen::Vector3d& p) {
  picks.push_back(p);
  const auto kind = static_cast<modeling::MeasureKind>(measure_kind);
  if (!modeling::takes_more_points(kind) && picks.size() >= modeling::points_needed(kind))
    finish_measurement();
}

void WorkbenchState::finish_measurement() {
  const auto kind = static_cast<modeling::MeasureKind>(measure_kind);
  if (picks.size() < modeling::points_needed(kind)) return;
  std::vector<modeling::Measurement> list = session.measurements();
  // "distance N", N one above the highest of the list: never a name twice.
  const std::string prefix = std::string(modeling::measure_kind_name(kind)) + " ";
  long next = 1;
  for (const modeling::Measurement& m : list) {
    if (m.name.rfind(prefix, 0) != 0) continue;
    next = std::max(next, std::strtol(m.name.c_str() + prefix.size(), nullptr, 10) + 1);
  }
  const std::string name = prefix + std::to_string(next);
  list.push_back({name, kind, picks});
  if (run("Saving " + name,
          [this, list, name] { session.save_measurements(list, "measured " + name); }))
    picks.clear();
}

std::optional<ImVec2> WorkbenchState::screen_of(const Eigen::Vector3d& p) const {
  const int w = static_cast<int>(view3d.w), h = static_cast<int>(view3d.h);
  if (w <= 0 || h <= 0 || !renderer) return std::nullopt;
  const render::RenderView view = render::make_render_view(navigation.camera(w, h), model_origin());
  const Eigen::Vector4f model((p - model_origin()).cast<float>().homogeneous());
  const Eigen::Vector4f clip = view.projection * view.view * model;
  if (clip.w() <= 1e-6f) return std::nullopt;
  const float nx = clip.x() / clip.w(), ny = clip.y() / clip.w();
  return ImVec2(view3d.x + 0.5f * (nx + 1.0f) * view3d.w, view3d.y + 0.5f * (1.0f - ny) * view3d.h);
}

}  // namespace scanbench::app::workbench

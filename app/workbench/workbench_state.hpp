// What the workbench's input layer, panels and views share: the session
// (the project and the tools, session.hpp), the 3D camera and renderer,
// the window's layout, the selection in the object tree, the colour
// editor's sliders, and the widgets' places for replays. The panels
// (panels.hpp) draw from it and act through it; the input layer
// (input.hpp) feeds it events.
#pragma once

#include <imgui.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "app/workbench/background_command.hpp"
#include "app/workbench/navigation.hpp"
#include "app/workbench/session.hpp"
#include "app/workbench/workbench.hpp"
#include "render/frame_budget.hpp"
#include "render/lod_renderer.hpp"
#include "render/pick.hpp"
#include "render/window/window_device.hpp"

namespace scanbench::app::workbench {

// The window's layout [pixels at scale 1, a 1280 × 800 window]: the project
// panel on the left, the tools across the top, the panoramic view above the
// 3D view, the status bar at the bottom. Panels, fonts and widgets grow
// with the window (WorkbenchState::ui_scale).
inline constexpr float kPanelWidth = 340.0f;
inline constexpr float kToolbarHeight = 64.0f;
inline constexpr float kStatusHeight = 26.0f;

struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
  bool contains(double px, double py) const {
    return px >= x && py >= y && px < x + w && py < y + h;
  }
};

// What a mouse drag moves.
enum class Drag { kNone, kOrbit, kPan3d, kPanPanorama, kLasso3d, kBrush3d };

// A question the workbench asks before an action it cannot simply take
// back, answered in a modal window (questions_panel).
struct Question {
  std::string title;
  std::string text;
  std::string yes;  // the action's button: "Undo geometry", "Delete"
  std::function<void()> on_yes;
};

// The colour editor's sliders.
struct ColorSliders {
  float brightness = 0.0f, contrast = 1.0f, gamma = 1.0f, hue = 0.0f, saturation = 1.0f;
};

struct WorkbenchState {
  WorkbenchState(const WorkbenchOptions& options, render::WindowDevice& window);

  const WorkbenchOptions& options;
  render::WindowDevice& window;
  Session session;

  // ---- The 3D view --------------------------------------------------------
  Navigation navigation;
  render::RenderSettings settings;
  // The store the session names, drawn streaming (render/lod_renderer.hpp):
  // moving frames keep to a time target through the point budget, then the
  // frames refine until the picture is complete.
  std::unique_ptr<render::LodRenderer> renderer;
  std::int64_t renderer_generation = -1;  // of the store it draws
  // Renderers opened, and updates in place the renderer followed keeping
  // its caches.
  int renderers_opened = 0, renderer_follows = 0;
  std::int64_t shown_revision = -1;       // the session's revision it was last told of
  // What it shows of the tree (ids, parents, visibility, colour edits) and
  // when the scans' corrections last changed.
  std::vector<std::tuple<std::int64_t, std::optional<std::int64_t>, bool, store::ColorEdit>>
      shown_objects;
  std::int64_t shown_corrections = -1;
  render::LodFramePlan last_plan;
  float frame_target_ms = 100.0f;
  render::FrameBudget budget{100.0};
  // The moving frames so far (the newest kMovingFramesKept): how long each
  // took, and how many drew more points than their budget or had none.
  static constexpr std::size_t kMovingFramesKept = 4096;
  std::vector<double> moving_frame_ms;
  std::size_t moving_frames = 0;
  std::size_t frames_over_budget = 0;
  double last_draw_ms = 0.0;  // the last 3D draw: wall time, finished on the device
  double last_gpu_ms = -1.0;  // ... and the device's own time (negative: unknown)
  bool view_dirty = true;     // the camera or what the view shows changed
  bool fly = false;

  // ---- What the 3D view draws: a clipping box and a slice (world [m]) ----
  bool clip_on = false;
  std::array<double, 3> clip_min = {0.0, 0.0, 0.0};
  std::array<double, 3> clip_max = {0.0, 0.0, 0.0};
  bool slice_on = false;
  int slice_axis = 2;  // across x, y or z
  double slice_at = 0.0;
  float slice_thickness = 0.5f;

  // ---- Measuring: left clicks in the 3D view pick points ----------------
  bool measuring = false;
  int measure_kind = 1;                         // modeling::MeasureKind
  std::vector<Eigen::Vector3d> picks;           // world [m], of the measurement being taken
  std::array<double, 2> press_at = {0.0, 0.0};  // where the left button went down
  std::array<char, 4096> csv_path{};            // where Export CSV writes

  // ---- Selecting in the 3D view: the lasso (or a box) and the brush ------
  std::vector<Eigen::Vector2f> lasso_3d;  // window points of the lasso being drawn
  bool box_3d = false;                    // a box from the first point to the cursor
  bool select_through = false;            // the lasso takes every depth, not the front only
  float select_depth_m = 0.0f;            // else how far behind the front surface it reaches
  float brush_radius_m = 0.25f;
  std::map<std::int64_t, std::vector<std::uint32_t>> brushed;  // the stroke so far
  // A sample of the last 3D selection's points (model frame), marked over
  // the view until the selection changes otherwise.
  std::vector<Eigen::Vector3f> selection_marks;
  std::int64_t marks_revision = -1;  // the session's revision they show
  // Starts a lasso (or, with `box`, a box) at window point (x, y) of the 3D view.
  void start_lasso_3d(double x, double y, bool box);
  void extend_lasso_3d(double x, double y);
  // The points the lasso encloses (in front, down to select_depth_m
  // behind, or every depth with select_through) join the selection by the
  // session's mode, as one step.
  void finish_lasso_3d();
  // The brush at window point (x, y): the points within its radius of the
  // surface under it join the stroke; finish_brush() selects the stroke.
  void brush_at(double x, double y);
  void finish_brush();
  // The lasso's polygon in the 3D view's picture pixels.
  std::vector<Eigen::Vector2f> lasso_3d_polygon() const;

  // ---- Layout and the panoramic view ------------------------------------
  Rect panorama;
  Rect view3d;
  float zoom = 1.0f;
  std::array<float, 2> pan = {0.0f, 0.0f};
  int panorama_channel = 0;  // PanoramaChannel
  unsigned panorama_texture = 0;
  std::array<std::int64_t, 4> panorama_key = {-1, -1, -1, -1};  // what the texture shows

  // ---- Input --------------------------------------------------------------
  std::set<int> held;  // keys down
  std::array<double, 2> cursor = {0.0, 0.0};
  Drag drag = Drag::kNone;

  // ---- The object tree and the colour editor ----------------------------
  std::array<char, 128> name = {'o', 'b', 'j', 'e', 'c', 't'};  // for commits, groups, renames
  std::set<std::int64_t> selected;
  std::int64_t primary_id = 0;
  ColorSliders color;
  std::array<bool, 5> touched{};  // the colour sliders moved since the node was selected
  // A drop in the object tree, made after the tree is drawn (the move
  // reloads the nodes the tree is walking): the node and its new parent.
  std::optional<std::pair<std::int64_t, std::optional<std::int64_t>>> pending_reparent;

  // ---- Replays and the status bar ----------------------------------------
  std::map<std::string, std::array<float, 2>> probes;  // widgets' centres by name
  // The window's frames: real intervals between them (live or replayed),
  // smoothed, for the frame rate the status bar shows.
  double frame_seconds = 0.0;
  std::int64_t frames = 0;
  std::chrono::steady_clock::time_point last_frame;

  std::string name_text() const { return std::string(name.data()); }

  // Places the views for a window of `width` × `height` pixels, and sets
  // the scale of the panels for it.
  void layout(int width, int height);
  // How much larger than at 1280 × 800 the panels, fonts and widgets are:
  // the smaller of the window's two ratios to that size, in steps of ¼
  // (a resize does not rebuild the fonts each pixel), 1 to 3.
  float ui_scale = 1.0f;
  // `pixels` at scale 1, scaled.
  float px(float pixels) const { return std::round(pixels * ui_scale); }

  // The panoramic view's scale [window pixels per scan pixel], the image
  // point (x = column, y = row, pixel centres at integers) under window
  // point (x, y), and the window point of an image point.
  float panorama_scale() const;
  std::array<double, 2> panorama_pixel(double x, double y) const;
  ImVec2 panorama_screen(const Eigen::Vector2d& pixel) const;

  // Records the last widget's centre under `name` (a slider's: its frame's).
  void probe(const std::string& widget);
  void probe_slider(const std::string& widget);

  // The selected node the colour editor and Frame act on, if any.
  std::optional<std::int64_t> primary() const;
  // A copy of node `id`: a command reloads the tree, so pointers into it do
  // not outlive one.
  std::optional<store::ObjectNode> node(std::int64_t id) const;
  // Node `id` and every node below it.
  std::set<std::int64_t> subtree(std::int64_t id) const;
  void select_only(std::int64_t id);
  void load_color_editor();
  // After undo or redo: a selection that is gone is dropped.
  void after_command();

  // The group of automatic proposals under review (proposals_panel).
  std::optional<std::int64_t> review_group;

  // The question being asked, if any; the panels are inert until answered.
  // Its answer runs as a background command labelled with its button.
  std::optional<Question> question;

  // ---- Commands run on a worker thread (background_command.hpp) ---------
  BackgroundCommand command;
  // Runs `work` (a session command and what follows it, such as selecting
  // what it made) as the background command `label`, starting once this
  // frame is drawn, and then builds what the views show next
  // (Session::prepare_views), so that the window's thread does not. False,
  // and nothing runs, while another is asked for or running: the caller
  // keeps what it would have cleared (the picks, the question).
  bool run(std::string label, std::function<void()> work);
  // The session's status when the last command ended: the status bar shows
  // how long the command took beside it, until something else says more.
  std::string command_status;

  // Ctrl+Z: takes back the workbench's own edits; before a batch stage
  // (import, geometry, register, merge, harmonize) it asks.
  void undo();
  void redo();
  // Deletes the selected node; a group with descendants only after asking.
  void remove_selected();

  // A new object from the selection, in the selected group if one is; a
  // group of the selected nodes.
  void commit();
  void group();

  // Frames the bulk of the model: per axis the 2nd to 98th percentile of a
  // sample of its points, so that far stray returns and the long splats of
  // distant ground do not shrink the site to a speck.
  void frame_whole_model();
  // Frames the selected node, or the whole model.
  void frame_selection();
  // Measuring: the point of the model drawn under window point (x, y) of
  // the 3D view joins the measurement being taken, which is saved once it
  // has its points (an area: on finish_measurement).
  void pick_at(double x, double y);
  // The same with a click at image point (x = column, y = row) of the
  // panoramic view: the scan's own sample there (Session::world_point).
  void pick_in_panorama(double x, double y);
  // A picked point joins the measurement being taken.
  void add_pick(const Eigen::Vector3d& p);
  void finish_measurement();
  // Selecting: the object drawn under window point (x, y) of the 3D view
  // becomes the selection, or with `toggle` (Ctrl) joins or leaves it; a
  // click on no object's points clears the selection (not with `toggle`).
  // What the view does not draw (hidden, clipped, sliced away) is not hit.
  void select_in_3d(double x, double y, bool toggle);
  // The point of the model drawn under window point (x, y) of the 3D view.
  std::optional<render::LodPick> point_under(double x, double y);
  // The 3D view shows all it will until something changes: no frame is
  // due (a move, a refinement, nodes loading), or there is nothing to draw.
  bool view_settled() const;
  // World = this + model frame: the store's origin (zero without one).
  Eigen::Vector3d model_origin() const;
  // Window point of world point `p` in the 3D view; none behind the eye.
  std::optional<ImVec2> screen_of(const Eigen::Vector3d& p) const;

  // The clipping box around the selected node (5 % wider), switched on.
  void clip_to_selection();
  // The box and slice above into the renderer's settings, relative to the
  // model's origin (the 3D view calls it once its model is current).
  void apply_clipping();
};

}  // namespace scanbench::app::workbench

#include "app/workbench/workbench.hpp"

#include <backends/imgui_impl_opengl3.h>
#include <epoxy/gl.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "acquisition/picture_file.hpp"
#include "app/workbench/navigation.hpp"
#include "app/workbench/replay.hpp"
#include "app/workbench/session.hpp"
#include "core/errors.hpp"
#include "render/render_view.hpp"
#include "render/splat_renderer.hpp"
#include "render/window/window_device.hpp"

namespace scanbench::app::workbench {

namespace {

namespace keys = render::keys;

// The window's fixed layout [pixels]: the project panel on the left, the
// tools across the top, the panoramic view above the 3D view, the status
// bar at the bottom.
constexpr float kPanelWidth = 340.0f;
constexpr float kToolbarHeight = 64.0f;
constexpr float kStatusHeight = 26.0f;
constexpr double kReplayFrameSeconds = 1.0 / 30.0;

struct Rect {
  float x = 0, y = 0, w = 0, h = 0;
  bool contains(double px, double py) const {
    return px >= x && py >= y && px < x + w && py < y + h;
  }
};

std::string node_label(const modeling::ObjectNode& node) {
  std::string label = node.name;
  if (node.hidden) label += " (hidden)";
  if (!node.color.empty()) label += " (recoloured)";
  label += "##" + std::to_string(node.id);
  return label;
}

class Workbench final : public render::WindowInput {
 public:
  Workbench(const WorkbenchOptions& options, render::WindowDevice& window)
      : options_(options), window_(window), session_(options.project) {
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;
    const std::array<std::pair<ImGuiKey, int>, 19> map = {{{ImGuiKey_Tab, keys::kTab},
                                                           {ImGuiKey_LeftArrow, keys::kLeft},
                                                           {ImGuiKey_RightArrow, keys::kRight},
                                                           {ImGuiKey_UpArrow, keys::kUp},
                                                           {ImGuiKey_DownArrow, keys::kDown},
                                                           {ImGuiKey_Home, keys::kHome},
                                                           {ImGuiKey_End, keys::kEnd},
                                                           {ImGuiKey_Delete, keys::kDelete},
                                                           {ImGuiKey_Backspace, keys::kBackspace},
                                                           {ImGuiKey_Space, keys::kSpace},
                                                           {ImGuiKey_Enter, keys::kEnter},
                                                           {ImGuiKey_Escape, keys::kEscape},
                                                           {ImGuiKey_KeyPadEnter, keys::kEnter},
                                                           {ImGuiKey_A, 'A'},
                                                           {ImGuiKey_C, 'C'},
                                                           {ImGuiKey_V, 'V'},
                                                           {ImGuiKey_X, 'X'},
                                                           {ImGuiKey_Y, 'Y'},
                                                           {ImGuiKey_Z, 'Z'}}};
    for (const auto& [imgui_key, code] : map) io.KeyMap[imgui_key] = code;
    glGenTextures(1, &panorama_texture_);
    frame_whole_model();
  }

  ~Workbench() override { glDeleteTextures(1, &panorama_texture_); }

  // ---- Input (WindowInput): live from GLFW, or from a replay ------------

  void cursor_moved(double x, double y) override {
    ImGui::GetIO().MousePos = ImVec2(static_cast<float>(x), static_cast<float>(y));
    const double dx = x - cursor_[0], dy = y - cursor_[1];
    cursor_ = {x, y};
    if (drag_ == Drag::kOrbit) {
      if (fly_) {
        navigation_.look(dx, dy);
      } else {
        navigation_.orbit(dx, dy);
      }
      view_dirty_ = true;
    } else if (drag_ == Drag::kPan3d) {
      navigation_.pan(dx, dy, view3d_.h);
      view_dirty_ = true;
    } else if (drag_ == Drag::kPanPanorama) {
      pan_[0] += static_cast<float>(dx);
      pan_[1] += static_cast<float>(dy);
    }
  }

  void button(int button, bool pressed, int mods) override {
    ImGuiIO& io = ImGui::GetIO();
    set_mods(pressed ? mods : 0);
    if (button >= 0 && button < 5) io.MouseDown[button] = pressed;
    if (!pressed) {
      drag_ = Drag::kNone;
      return;
    }
    if (io.WantCaptureMouse) return;  // the panels have it
    const auto [x, y] = cursor_;
    if (panorama_.contains(x, y)) {
      if (button == 0) {
        const auto [col, row] = panorama_pixel(x, y);
        session_.click(col, row);
      } else {
        drag_ = Drag::kPanPanorama;
      }
    } else if (view3d_.contains(x, y)) {
      drag_ = button == 0 ? Drag::kOrbit : Drag::kPan3d;
    }
  }

  void scrolled(double, double dy) override {
    ImGuiIO& io = ImGui::GetIO();
    io.MouseWheel += static_cast<float>(dy);
    if (io.WantCaptureMouse) return;
    const auto [x, y] = cursor_;
    if (panorama_.contains(x, y)) {
      // Zoom about the cursor: the pixel under it stays under it.
      const auto [col, row] = panorama_pixel(x, y);
      zoom_ = std::clamp(zoom_ * static_cast<float>(std::pow(1.25, dy)), 1.0f, 64.0f);
      const float scale = panorama_scale();
      pan_[0] = static_cast<float>(x) - panorama_.x - static_cast<float>(col) * scale;
      pan_[1] = static_cast<float>(y) - panorama_.y - static_cast<float>(row) * scale;
    } else if (view3d_.contains(x, y)) {
      navigation_.zoom(dy);
      view_dirty_ = true;
    }
  }

  void key(int key, bool pressed, int mods) override {
    ImGuiIO& io = ImGui::GetIO();
    if (key >= 0 && key < 512) io.KeysDown[key] = pressed;
    if (pressed) {
      held_.insert(key);
    } else {
      held_.erase(key);
    }
    // A key's modifiers hold while it is down; after that only the
    // modifier keys still held count (a replayed Ctrl+Z lets Ctrl go).
    set_mods(pressed ? mods : 0);
    if (!pressed || io.WantTextInput) return;
    // Undo and redo work wherever the keyboard is, text fields excepted
    // (they have their own).
    const bool control = (mods & keys::kModControl) != 0;
    if (control && key == 'Z' && (mods & keys::kModShift) == 0) {
      session_.undo();
      after_command();
      return;
    }
    if (control && (key == 'Y' || (key == 'Z' && (mods & keys::kModShift) != 0))) {
      session_.redo();
      after_command();
      return;
    }
    // Letter shortcuts act unless a text field has the keyboard (not "any
    // widget": a click on a tree node would otherwise swallow the next key).
    if (control) return;
    switch (key) {
      case 'S':
        session_.tool = Tool::kSeed;
        break;
      case 'L':
        session_.tool = Tool::kLasso;
        break;
      case 'B':
        session_.tool = Tool::kBarrier;
        break;
      case keys::kEnter:
        session_.finish_polyline();
        break;
      case keys::kEscape:
        session_.clear_constraints();
        break;
      case 'C':
        commit();
        break;
      case 'G':
        group();
        break;
      case 'F':
        frame_selection();
        break;
      case 'V':
        fly_ = !fly_;
        break;
      default:
        break;
    }
  }

  void text(unsigned codepoint) override { ImGui::GetIO().AddInputCharacter(codepoint); }

  // ---- Frames ------------------------------------------------------------

  void frame(double seconds) {
    ImGuiIO& io = ImGui::GetIO();
    const auto [width, height] = window_.framebuffer_size();
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DeltaTime = static_cast<float>(std::max(seconds, 1e-4));
    frame_seconds_ = frames_ == 0 ? seconds : 0.9 * frame_seconds_ + 0.1 * seconds;
    layout(width, height);
    fly_keys(seconds);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
    project_panel();
    toolbar();
    panorama_view();
    view_3d();
    status_bar();
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClearColor(0.11f, 0.12f, 0.14f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    ++frames_;
  }

  // The window as last drawn (before the buffers swap) into a PNG.
  void screenshot(const std::filesystem::path& file) const {
    const auto [width, height] = window_.framebuffer_size();
    std::vector<std::uint8_t> bottom_up(3 * static_cast<std::size_t>(width) * height);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
    std::vector<std::uint8_t> rgb(bottom_up.size());
    const std::size_t row = 3 * static_cast<std::size_t>(width);
    for (int y = 0; y < height; ++y) {
      std::copy_n(bottom_up.begin() + static_cast<std::ptrdiff_t>(row * (height - 1 - y)), row,
                  rgb.begin() + static_cast<std::ptrdiff_t>(row * y));
    }
    acquisition::write_rgb_picture(file, width, height, rgb);
  }

  // The centres of the named widgets and where the views are, for tests
  // that write replays.
  void write_layout(const std::filesystem::path& file) const {
    nlohmann::json widgets = nlohmann::json::object();
    for (const auto& [name, at] : probes_) widgets[name] = {at[0], at[1]};
    const nlohmann::json out = {{"widgets", widgets},
                                {"panorama",
                                 {{"x", panorama_.x + pan_[0]},
                                  {"y", panorama_.y + pan_[1]},
                                  {"scale", panorama_scale()},
                                  {"columns", session_.scan().columns},
                                  {"rows", session_.scan().rows}}},
                                {"view3d", {view3d_.x, view3d_.y, view3d_.w, view3d_.h}}};
    std::ofstream stream(file);
    stream << out.dump(1) << "\n";
    if (!stream.flush()) throw core::RuntimeFailure(file.string(), {}, "cannot write the layout");
  }

 private:
  enum class Drag { kNone, kOrbit, kPan3d, kPanPanorama };

  std::string name() const { return std::string(name_.data()); }

  // ImGui's modifier state: the modifier keys held, and `mods` of the event.
  void set_mods(int mods) {
    ImGuiIO& io = ImGui::GetIO();
    const auto held = [&](int left, int right) {
      return held_.count(left) != 0 || held_.count(right) != 0;
    };
    io.KeyCtrl = held(keys::kLeftControl, keys::kRightControl) || (mods & keys::kModControl) != 0;
    io.KeyShift = held(keys::kLeftShift, keys::kRightShift) || (mods & keys::kModShift) != 0;
    io.KeyAlt = held(keys::kLeftAlt, keys::kRightAlt) || (mods & keys::kModAlt) != 0;
  }

  void layout(int width, int height) {
    const float w = static_cast<float>(width), h = static_cast<float>(height);
    const float views_height = h - kToolbarHeight - kStatusHeight;
    panorama_ = {kPanelWidth, kToolbarHeight, w - kPanelWidth, std::round(0.45f * views_height)};
    view3d_ = {kPanelWidth, panorama_.y + panorama_.h, w - kPanelWidth, views_height - panorama_.h};
  }

  float panorama_scale() const {
    return panorama_.w / static_cast<float>(std::max(session_.scan().columns, 1)) * zoom_;
  }

  std::array<double, 2> panorama_pixel(double x, double y) const {
    const float scale = panorama_scale();
    return {(x - panorama_.x - pan_[0]) / scale, (y - panorama_.y - pan_[1]) / scale};
  }

  ImVec2 panorama_screen(const Eigen::Vector2d& pixel) const {
    const float scale = panorama_scale();
    return ImVec2(panorama_.x + pan_[0] + static_cast<float>(pixel.x()) * scale,
                  panorama_.y + pan_[1] + static_cast<float>(pixel.y()) * scale);
  }

  void probe(const std::string& name) {
    const ImVec2 low = ImGui::GetItemRectMin(), high = ImGui::GetItemRectMax();
    probes_[name] = {0.5f * (low.x + high.x), 0.5f * (low.y + high.y)};
  }

  // A slider's probe: the centre of its frame, not of frame and label.
  void probe_slider(const std::string& name) {
    const ImVec2 low = ImGui::GetItemRectMin(), high = ImGui::GetItemRectMax();
    probes_[name] = {low.x + 0.5f * ImGui::CalcItemWidth(), 0.5f * (low.y + high.y)};
  }

  void fly_keys(double seconds) {
    if (!fly_ || ImGui::GetIO().WantTextInput) return;
    const auto held = [&](int key) { return held_.count(key) ? 1.0 : 0.0; };
    const double forward = held('W') - held('S');
    const double right = held('D') - held('A');
    const double up = held('E') - held('Q');
    if (forward == 0.0 && right == 0.0 && up == 0.0) return;
    navigation_.fly(forward, right, up, seconds);
    view_dirty_ = true;
  }

  void after_command() {
    if (selected_.size() == 1 &&
        !std::any_of(session_.nodes().begin(), session_.nodes().end(),
                     [&](const auto& n) { return n.id == *selected_.begin(); }))
      selected_.clear();
    load_color_editor();
  }

  std::optional<std::int64_t> primary() const {
    if (selected_.empty()) return std::nullopt;
    return primary_;
  }

  // A copy of node `id`: a command reloads the tree, so pointers into it do
  // not outlive one.
  std::optional<modeling::ObjectNode> node(std::int64_t id) const {
    for (const modeling::ObjectNode& n : session_.nodes())
      if (n.id == id) return n;
    return std::nullopt;
  }

  // A new object from the selection, in the selected group if one is.
  void commit() {
    std::optional<std::int64_t> parent;
    if (const auto p = primary(); p && node(*p)) {
      const modeling::ObjectNode n = *node(*p);
      parent = n.kind == modeling::NodeKind::kGroup ? std::optional(n.id) : n.parent;
    }
    if (session_.commit(name(), parent)) {
      const std::int64_t made = session_.nodes().empty() ? 0 : session_.nodes().back().id;
      select_only(made);
    }
  }

  void group() {
    const std::vector<std::int64_t> children(selected_.begin(), selected_.end());
    if (session_.group(name(), children)) select_only(session_.nodes().back().id);
  }

  void select_only(std::int64_t id) {
    selected_ = {id};
    primary_ = id;
    load_color_editor();
  }

  void load_color_editor() {
    color_ = {};
    touched_ = {};
    const auto p = primary();
    if (!p || !node(*p)) return;
    const modeling::ColorEdit own = node(*p)->color;
    color_.brightness = static_cast<float>(own.brightness.value_or(0.0));
    color_.contrast = static_cast<float>(own.contrast.value_or(1.0));
    color_.gamma = static_cast<float>(own.gamma.value_or(1.0));
    color_.hue = static_cast<float>(own.hue_deg.value_or(0.0));
    color_.saturation = static_cast<float>(own.saturation.value_or(1.0));
  }

  // Frames the bulk of the model: per axis the 2nd to 98th percentile of a
  // sample of its points, so that far stray returns and the long splats of
  // distant ground do not shrink the site to a speck.
  void frame_whole_model() {
    const modeling::RenderModel& model = session_.render_model();
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
    navigation_.frame(box);
    view_dirty_ = true;
  }

  void frame_selection() {
    const auto p = primary();
    const std::optional<modeling::ObjectNode> n = p ? node(*p) : std::nullopt;
    if (n && n->bbox_world) {
      navigation_.frame(*n->bbox_world);
      view_dirty_ = true;
    } else {
      frame_whole_model();
    }
  }

  // ---- Panels ------------------------------------------------------------

  static void place(float x, float y, float w, float h) {
    ImGui::SetNextWindowPos(ImVec2(x, y));
    ImGui::SetNextWindowSize(ImVec2(w, h));
  }

  static constexpr ImGuiWindowFlags kFixed =
      ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;

  void project_panel() {
    const float h = ImGui::GetIO().DisplaySize.y - kStatusHeight;
    place(0, 0, kPanelWidth, h);
    ImGui::Begin("Project", nullptr, kFixed);
    scans_section();
    objects_section();
    color_section();
    view_section();
    ImGui::End();
  }

  void scans_section() {
    if (!ImGui::CollapsingHeader("Scans", ImGuiTreeNodeFlags_DefaultOpen)) return;
    for (const modeling::StoredScanSummary& s : session_.scans()) {
      const bool current = s.id == session_.scan_id();
      const std::string label = std::to_string(s.id) + "  " + s.summary.name;
      if (ImGui::Selectable(label.c_str(), current) && !current) {
        session_.open_scan(s.id);
        zoom_ = 1.0f;
        pan_ = {0.0f, 0.0f};
      }
      probe("scan " + std::to_string(s.id));
      if (ImGui::IsItemHovered()) {
        const Eigen::Vector3d t = s.summary.T_world_scan.translation();
        ImGui::SetTooltip("%d × %d, %zu valid points\nat %.3f %.3f %.3f m", s.summary.rows,
                          s.summary.columns, s.summary.valid_points, t.x(), t.y(), t.z());
      }
    }
    // The shown scan's pose: its scanner's position and heading in the world.
    for (const modeling::StoredScanSummary& s : session_.scans()) {
      if (s.id != session_.scan_id()) continue;
      const Eigen::Isometry3d& pose = s.summary.T_world_scan;
      const Eigen::Vector3d t = pose.translation();
      const Eigen::Vector3d x = pose.linear().col(0);
      const double heading = std::atan2(x.y(), x.x()) * 180.0 / 3.14159265358979323846;
      const double tilt =
          std::acos(std::clamp(pose.linear()(2, 2), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
      ImGui::TextWrapped("pose: at %.3f, %.3f, %.3f m; heading %.2f°, tilt %.2f°", t.x(), t.y(),
                         t.z(), heading, tilt);
    }
    if (const auto report = session_.project().latest_result("register")) {
      if (ImGui::TreeNode("Registration report")) {
        const nlohmann::json j = nlohmann::json::parse(*report, nullptr, false);
        ImGui::TextWrapped("%s", j.is_discarded() ? report->c_str() : j.dump(1).c_str());
        ImGui::TreePop();
      }
    }
  }

  void node_tree(const modeling::ObjectNode& n,
                 const std::map<std::int64_t, std::vector<const modeling::ObjectNode*>>& children) {
    ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_DefaultOpen |
                               ImGuiTreeNodeFlags_SpanAvailWidth;
    if (selected_.count(n.id)) flags |= ImGuiTreeNodeFlags_Selected;
    const auto found = children.find(n.id);
    if (found == children.end()) flags |= ImGuiTreeNodeFlags_Leaf;
    const bool open = ImGui::TreeNodeEx(node_label(n).c_str(), flags);
    probe("node " + n.name);
    if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) {
      if (ImGui::GetIO().KeyCtrl) {
        if (!selected_.erase(n.id)) selected_.insert(n.id);
        primary_ = n.id;
        load_color_editor();
      } else {
        select_only(n.id);
      }
    }
    if (ImGui::BeginDragDropSource()) {
      ImGui::SetDragDropPayload("scanbench-node", &n.id, sizeof n.id);
      ImGui::Text("move %s", n.name.c_str());
      ImGui::EndDragDropSource();
    }
    if (n.kind == modeling::NodeKind::kGroup && ImGui::BeginDragDropTarget()) {
      if (const ImGuiPayload* payload = ImGui::AcceptDragDropPayload("scanbench-node")) {
        std::int64_t moved = 0;
        std::memcpy(&moved, payload->Data, sizeof moved);
        if (moved != n.id) pending_reparent_ = {moved, n.id};
      }
      ImGui::EndDragDropTarget();
    }
    if (!open) return;
    if (found != children.end()) {
      for (const modeling::ObjectNode* child : found->second) node_tree(*child, children);
    }
    ImGui::TreePop();
  }

  void objects_section() {
    if (!ImGui::CollapsingHeader("Objects", ImGuiTreeNodeFlags_DefaultOpen)) return;
    std::map<std::int64_t, std::vector<const modeling::ObjectNode*>> children;
    std::vector<const modeling::ObjectNode*> roots;
    std::set<std::int64_t> ids;
    for (const modeling::ObjectNode& n : session_.nodes()) ids.insert(n.id);
    for (const modeling::ObjectNode& n : session_.nodes()) {
      if (n.parent && ids.count(*n.parent)) {
        children[*n.parent].push_back(&n);
      } else {
        roots.push_back(&n);
      }
    }
    ImGui::BeginChild("tree", ImVec2(0, 190), true);
    if (roots.empty()) ImGui::TextDisabled("no objects yet: click a seed, then Commit");
    for (const modeling::ObjectNode* root : roots) node_tree(*root, children);
    ImGui::EndChild();
    // A drop outside every group moves the node to the roots.
    if (ImGui::BeginDragDropTarget()) {
      if (const ImGuiPayload* payload = ImGui::AcceptDragDropPayload("scanbench-node")) {
        std::int64_t moved = 0;
        std::memcpy(&moved, payload->Data, sizeof moved);
        pending_reparent_ = {moved, std::nullopt};
      }
      ImGui::EndDragDropTarget();
    }
    if (pending_reparent_) {
      session_.reparent(pending_reparent_->first, pending_reparent_->second);
      pending_reparent_.reset();
    }
    const auto p = primary();
    ImGui::BeginDisabled(selected_.empty());
    if (ImGui::Button("Group")) group();
    probe("group");
    ImGui::SameLine();
    if (ImGui::Button("Rename") && p) session_.rename(*p, name());
    probe("rename");
    ImGui::SameLine();
    const std::optional<modeling::ObjectNode> n = p ? node(*p) : std::nullopt;
    if (ImGui::Button(n && n->hidden ? "Show" : "Hide") && n)
      session_.set_hidden(n->id, !n->hidden);
    probe("hide");
    ImGui::SameLine();
    if (ImGui::Button("Delete") && p) {
      session_.remove(*p);
      selected_.clear();
    }
    probe("delete");
    ImGui::SameLine();
    if (ImGui::Button("Separate") && p) session_.separate(*p);
    probe("separate");
    ImGui::SameLine();
    if (ImGui::Button("Frame")) frame_selection();
    probe("frame");
    ImGui::EndDisabled();
  }

  void color_section() {
    if (!ImGui::CollapsingHeader("Colour", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const auto p = primary();
    const std::optional<modeling::ObjectNode> n = p ? node(*p) : std::nullopt;
    ImGui::Text("%s", n ? n->name.c_str() : "select an object to edit its colours");
    // Present without a selection too (disabled), so the panel below keeps
    // its place.
    ImGui::BeginDisabled(!n);
    touched_[0] |= ImGui::SliderFloat("brightness", &color_.brightness, -50.0f, 50.0f, "%.1f");
    probe_slider("brightness");
    touched_[1] |= ImGui::SliderFloat("contrast", &color_.contrast, 0.2f, 3.0f, "%.2f");
    probe_slider("contrast");
    touched_[2] |= ImGui::SliderFloat("gamma", &color_.gamma, 0.2f, 5.0f, "%.2f");
    probe_slider("gamma");
    touched_[3] |= ImGui::SliderFloat("hue", &color_.hue, -180.0f, 180.0f, "%.0f°");
    probe_slider("hue");
    touched_[4] |= ImGui::SliderFloat("saturation", &color_.saturation, 0.0f, 3.0f, "%.2f");
    probe_slider("saturation");
    // Apply sets what was moved (and keeps what the node set before); the
    // rest it goes on inheriting.
    if (ImGui::Button("Apply") && n) {
      modeling::ColorEdit set;
      if (touched_[0]) set.brightness = color_.brightness;
      if (touched_[1]) set.contrast = color_.contrast;
      if (touched_[2]) set.gamma = color_.gamma;
      if (touched_[3]) set.hue_deg = color_.hue;
      if (touched_[4]) set.saturation = color_.saturation;
      if (!set.empty()) session_.recolor(n->id, set, false);
      load_color_editor();
    }
    probe("apply colour");
    ImGui::SameLine();
    if (ImGui::Button("Inherit") && n) {
      session_.recolor(n->id, {}, true);
      load_color_editor();
    }
    probe("inherit colour");
    ImGui::SameLine();
    // Clone: the other selected node is the source.
    const bool two = n && selected_.size() == 2;
    ImGui::BeginDisabled(!two);
    if (ImGui::Button("Clone from other") && two) {
      const std::int64_t source =
          *selected_.begin() == n->id ? *selected_.rbegin() : *selected_.begin();
      session_.clone(source, n->id);
      load_color_editor();
    }
    probe("clone colour");
    ImGui::EndDisabled();
    ImGui::EndDisabled();
  }

  void view_section() {
    if (!ImGui::CollapsingHeader("3D view", ImGuiTreeNodeFlags_DefaultOpen)) return;
    bool changed = false;
    int kernel = static_cast<int>(settings_.kernel);
    changed |= ImGui::Combo("kernel", &kernel, "disk\0gaussian\0cosine\0");
    settings_.kernel = static_cast<render::Kernel>(kernel);
    changed |= ImGui::SliderFloat("splat scale", &settings_.splat_scale, 0.5f, 4.0f, "%.2f");
    bool blended = settings_.mode == render::DrawMode::kBlended;
    changed |= ImGui::Checkbox("two-pass blending", &blended);
    settings_.mode = blended ? render::DrawMode::kBlended : render::DrawMode::kSplats;
    int budget = static_cast<int>(settings_.culling.budget / 1000);
    changed |= ImGui::SliderInt("budget (k)", &budget, 50, 8000);
    settings_.culling.budget = static_cast<std::size_t>(budget) * 1000;
    int color = static_cast<int>(settings_.color);
    changed |= ImGui::Combo("colour", &color, "colour\0intensity\0height\0normal\0object\0");
    settings_.color = static_cast<render::ColorMode>(color);
    int navigation = fly_ ? 1 : 0;
    ImGui::RadioButton("orbit", &navigation, 0);
    probe("orbit");
    ImGui::SameLine();
    ImGui::RadioButton("walk/fly (W A S D Q E)", &navigation, 1);
    probe("fly");
    fly_ = navigation == 1;
    ImGui::Text("speed %.1f m/s", navigation_.speed_m_per_s());
    if (changed) view_dirty_ = true;
  }

  void toolbar() {
    const float w = ImGui::GetIO().DisplaySize.x - kPanelWidth;
    place(kPanelWidth, 0, w, kToolbarHeight);
    ImGui::Begin("Tools", nullptr, kFixed | ImGuiWindowFlags_NoTitleBar);
    int tool = static_cast<int>(session_.tool);
    ImGui::RadioButton("seed (S)", &tool, 0);
    probe("tool seed");
    ImGui::SameLine();
    ImGui::RadioButton("lasso (L)", &tool, 1);
    probe("tool lasso");
    ImGui::SameLine();
    ImGui::RadioButton("barrier (B)", &tool, 2);
    probe("tool barrier");
    session_.tool = static_cast<Tool>(tool);
    ImGui::SameLine();
    ImGui::SetNextItemWidth(100);
    int channel = static_cast<int>(session_.channel);
    if (ImGui::Combo("##channel", &channel, "range\0colour\0intensity\0normal\0")) {
      session_.channel = static_cast<segmentation::Channel>(channel);
      session_.tolerance = segmentation::default_grow_settings(session_.channel).tolerance;
    }
    probe("channel");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(90);
    float tolerance = static_cast<float>(session_.tolerance);
    // Units by channel (region_grow.hpp): range in footprints, colour in
    // ΔE, intensity in shares of the scan's spread, normal in degrees.
    if (ImGui::DragFloat("tolerance", &tolerance, 0.01f * std::max(tolerance, 0.01f), 0.001f,
                         100.0f, "%.3g"))
      session_.tolerance = tolerance;
    ImGui::SameLine();
    int mode = static_cast<int>(session_.mode);
    ImGui::RadioButton("new", &mode, 0);
    ImGui::SameLine();
    ImGui::RadioButton("add", &mode, 1);
    probe("mode add");
    ImGui::SameLine();
    ImGui::RadioButton("subtract", &mode, 2);
    session_.mode = static_cast<modeling::SelectMode>(mode);
    ImGui::SameLine();
    if (ImGui::Button("Clear lasso")) session_.clear_constraints();
    commands_row();
    ImGui::End();
  }

  // The toolbar's second row: the name for commits, groups and renames,
  // commit, proposals, the panoramic view's channel, undo and redo.
  void commands_row() {
    ImGui::SetNextItemWidth(220);
    if (ImGui::InputText("name", name_.data(), name_.size(),
                         ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll))
      commit();
    probe("name");
    ImGui::SameLine();
    ImGui::BeginDisabled(session_.selected_pixels() == 0);
    if (ImGui::Button("Commit (C)")) commit();
    probe("commit");
    ImGui::EndDisabled();
    ImGui::SameLine();
    if (ImGui::Button("Automatic proposals")) session_.propose();
    probe("propose");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(110);
    ImGui::Combo("view", &panorama_channel_, "colour\0range\0intensity\0normals\0");
    probe("panorama channel");
    ImGui::SameLine();
    if (ImGui::Button("Undo")) {
      session_.undo();
      after_command();
    }
    probe("undo");
    ImGui::SameLine();
    if (ImGui::Button("Redo")) {
      session_.redo();
      after_command();
    }
    probe("redo");
  }

  void status_bar() {
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    place(0, size.y - kStatusHeight, size.x, kStatusHeight);
    ImGui::Begin("Status", nullptr,
                 kFixed | ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoScrollbar);
    const render::FramePlan& plan = last_plan_;
    ImGui::Text(
        "%s | selection %zu px | 3D: %zu of %zu points drawn (frustum %zu, backface %zu, "
        "detail/budget %zu) in %.0f ms | %.1f frames/s",
        session_.status().empty() ? "ready" : session_.status().c_str(), session_.selected_pixels(),
        plan.submitted, plan.points, plan.culled_frustum, plan.culled_backface, plan.culled_budget,
        last_draw_ms_, frame_seconds_ > 0 ? 1.0 / frame_seconds_ : 0.0);
    ImGui::End();
  }

  // ---- Views (drawn behind the panels; input reaches them when ImGui does
  // not want it) ----------------------------------------------------------

  void panorama_view() {
    const std::array<std::int64_t, 3> key = {session_.revision(), panorama_channel_,
                                             session_.scan_id()};
    if (key != panorama_key_) {
      const Picture picture = session_.panorama(static_cast<PanoramaChannel>(panorama_channel_));
      glBindTexture(GL_TEXTURE_2D, panorama_texture_);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, picture.width, picture.height, 0, GL_RGBA,
                   GL_UNSIGNED_BYTE, picture.rgba.data());
      panorama_key_ = key;
    }
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    const ImVec2 low(panorama_.x, panorama_.y),
        high(panorama_.x + panorama_.w, panorama_.y + panorama_.h);
    draw->PushClipRect(low, high, true);
    draw->AddRectFilled(low, high, IM_COL32(20, 20, 24, 255));
    const acquisition::Scan& scan = session_.scan();
    draw->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(panorama_texture_)),
        panorama_screen({0.0, 0.0}),
        panorama_screen({static_cast<double>(scan.columns), static_cast<double>(scan.rows)}));
    const auto polyline = [&](const segmentation::Polyline& line, ImU32 colour, bool closed) {
      std::vector<ImVec2> points;
      for (const Eigen::Vector2d& v : line) points.push_back(panorama_screen(v));
      if (points.empty()) return;
      draw->AddPolyline(points.data(), static_cast<int>(points.size()), colour,
                        closed ? ImDrawFlags_Closed : 0, 2.0f);
      for (const ImVec2& p : points) draw->AddCircleFilled(p, 3.0f, colour);
    };
    polyline(session_.lasso(), IM_COL32(80, 220, 255, 255), session_.lasso_closed());
    for (const segmentation::Polyline& b : session_.barriers())
      polyline(b, IM_COL32(255, 70, 70, 255), false);
    draw->PopClipRect();
  }

  void view_3d() {
    const int w = static_cast<int>(view3d_.w), h = static_cast<int>(view3d_.h);
    if (w <= 0 || h <= 0) return;
    if (session_.render_model_stale() || !renderer_) {
      renderer_.reset();
      renderer_ = std::make_unique<render::SplatRenderer>(session_.render_model());
      view_dirty_ = true;
    }
    if (view_dirty_) {
      const render::RenderView view =
          render::make_render_view(navigation_.camera(w, h), session_.render_model().origin);
      const render::FrameResult frame = renderer_->draw(view, settings_);
      last_plan_ = frame.plan;
      last_draw_ms_ = frame.frame_ms;
      // Back to the state ImGui's renderer expects.
      glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
      glDisable(GL_PROGRAM_POINT_SIZE);
      glDisable(GL_DEPTH_TEST);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      view_dirty_ = false;
    }
    const render::SplatRenderer::PictureTexture picture = renderer_->picture_texture();
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    // The texture's bottom row first: flipped.
    draw->AddImage(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(picture.texture)),
                   ImVec2(view3d_.x, view3d_.y),
                   ImVec2(view3d_.x + view3d_.w, view3d_.y + view3d_.h),
                   ImVec2(picture.uv[0], picture.uv[3]), ImVec2(picture.uv[2], picture.uv[1]));
    draw->AddText(ImVec2(view3d_.x + 8, view3d_.y + 6), IM_COL32(255, 255, 255, 200),
                  fly_ ? "walk/fly: W A S D Q E, drag to look"
                       : "orbit: drag to turn, right-drag to pan, wheel to zoom");
  }

  const WorkbenchOptions& options_;
  render::WindowDevice& window_;
  Session session_;
  Navigation navigation_;
  render::RenderSettings settings_ = [] {
    render::RenderSettings s;
    s.culling.budget = 1'500'000;
    return s;
  }();
  std::unique_ptr<render::SplatRenderer> renderer_;
  render::FramePlan last_plan_;
  double last_draw_ms_ = 0.0;
  bool view_dirty_ = true;
  bool fly_ = false;
  std::set<int> held_;
  Rect panorama_;
  Rect view3d_;
  float zoom_ = 1.0f;
  std::array<float, 2> pan_ = {0.0f, 0.0f};
  int panorama_channel_ = 0;
  GLuint panorama_texture_ = 0;
  std::array<std::int64_t, 3> panorama_key_ = {-1, -1, -1};
  std::array<double, 2> cursor_ = {0.0, 0.0};
  Drag drag_ = Drag::kNone;
  std::array<char, 128> name_ = {'o', 'b', 'j', 'e', 'c', 't'};
  std::set<std::int64_t> selected_;
  std::int64_t primary_ = 0;
  struct {
    float brightness = 0.0f, contrast = 1.0f, gamma = 1.0f, hue = 0.0f, saturation = 1.0f;
  } color_;
  std::array<bool, 5> touched_{};  // the colour sliders moved since the node was selected
  // A drop in the object tree, made after the tree is drawn (the move
  // reloads the nodes the tree is walking): the node and its new parent.
  std::optional<std::pair<std::int64_t, std::optional<std::int64_t>>> pending_reparent_;
  std::map<std::string, std::array<float, 2>> probes_;
  double frame_seconds_ = 0.0;
  std::int64_t frames_ = 0;
};

// Feeds one replay event through the window's input path.
void feed(Workbench& bench, const ReplayEvent& e) {
  using Kind = ReplayEvent::Kind;
  switch (e.kind) {
    case Kind::kMove:
      bench.cursor_moved(e.x, e.y);
      break;
    case Kind::kButton:
      bench.button(e.button, e.pressed, e.mods);
      break;
    case Kind::kScroll:
      bench.scrolled(0.0, e.scroll);
      break;
    case Kind::kKey:
      bench.key(e.key, e.pressed, e.mods);
      break;
    case Kind::kText:
      bench.text(e.codepoint);
      break;
    case Kind::kWait:
    case Kind::kScreenshot:
      break;
  }
}

// ImGui's context and OpenGL renderer for the life of the workbench.
struct ImGuiScope {
  ImGuiScope() {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::StyleColorsDark();
    ImGui_ImplOpenGL3_Init("#version 450");
  }
  ~ImGuiScope() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiScope(const ImGuiScope&) = delete;
  ImGuiScope& operator=(const ImGuiScope&) = delete;
};

}  // namespace

void run_workbench(const WorkbenchOptions& options) {
  // Bad input first, before a window opens.
  const std::vector<ReplayEvent> events =
      options.replay.empty() ? std::vector<ReplayEvent>{} : read_replay(options.replay);
  render::WindowDevice window(options.width, options.height, "scanbench workbench");
  const ImGuiScope imgui;
  Workbench bench(options, window);
  window.set_input(&bench);
  struct Detach {
    render::WindowDevice& window;
    ~Detach() { window.set_input(nullptr); }
  } detach{window};

  if (!options.replay.empty()) {
    bench.frame(kReplayFrameSeconds);  // the first frame lays the panels out
    window.swap_buffers();
    for (const ReplayEvent& e : events) {
      feed(bench, e);
      bench.frame(kReplayFrameSeconds);
      if (e.kind == ReplayEvent::Kind::kScreenshot) bench.screenshot(e.file);
      window.swap_buffers();
    }
    bench.frame(kReplayFrameSeconds);
    if (!options.screenshot.empty()) bench.screenshot(options.screenshot);
    if (!options.layout.empty()) bench.write_layout(options.layout);
    return;
  }
  auto last = std::chrono::steady_clock::now();
  bool layout_written = false;
  while (!window.close_requested()) {
    window.poll_events();
    const auto now = std::chrono::steady_clock::now();
    bench.frame(std::chrono::duration<double>(now - last).count());
    last = now;
    if (!layout_written && !options.layout.empty()) {
      bench.write_layout(options.layout);
      layout_written = true;
    }
    if (!options.screenshot.empty()) {
      bench.screenshot(options.screenshot);
      return;  // a screenshot of the opened project is all that was asked for
    }
    window.swap_buffers();
  }
}

}  // namespace scanbench::app::workbench

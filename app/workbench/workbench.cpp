// The workbench's frame loop: the state (workbench_state.hpp) fed by the
// input layer (input.hpp), the panels and views (panels.hpp) drawn each
// frame, live or from a replay, and the screenshots and layouts that tests
// and the user guide take.
#include "app/workbench/workbench.hpp"

#include <backends/imgui_impl_opengl3.h>
#include <epoxy/gl.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "acquisition/formats/json_input.hpp"
#include "acquisition/formats/picture_file.hpp"
#include "app/workbench/input.hpp"
#include "app/workbench/panels.hpp"
#include "app/workbench/replay.hpp"
#include "core/errors.hpp"

namespace scanbench::app::workbench {

namespace {

constexpr double kReplayFrameSeconds = 1.0 / 30.0;
// While a command runs, the window repaints at most this often, leaving the
// cores to the command.
constexpr auto kWaitingFrame = std::chrono::milliseconds(50);

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

class Workbench {
 public:
  Workbench(const WorkbenchOptions& options, render::WindowDevice& window)
      : state_(options, window), input_(state_) {
    glGenTextures(1, &state_.panorama_texture);
    glGenTextures(1, &frozen_texture_);
    state_.frame_whole_model();
  }
  ~Workbench() {
    state_.command.wait();
    glDeleteTextures(1, &state_.panorama_texture);
    glDeleteTextures(1, &frozen_texture_);
  }
  Workbench(const Workbench&) = delete;
  Workbench& operator=(const Workbench&) = delete;

  WorkbenchInput& input() { return input_; }

  // Whether a background command runs: the frames show it, not the panels.
  bool busy() const { return state_.command.running(); }
  // No command runs or waits to, and the 3D view shows all it will: what a
  // screenshot waits for, as a user waits for the picture to settle.
  bool settled() const { return !busy() && !state_.command.asked() && state_.view_settled(); }

  // The session ends, once the command running has: the selections are
  // kept in the project (Session::keep_selections). Throws
  // core::RuntimeFailure when they cannot be.
  void end_session() {
    state_.command.wait();
    state_.command.collect();  // rethrows what it threw
    if (!state_.session.keep_selections(true)) {
      throw core::RuntimeFailure(state_.session.project().path().string(), {},
                                 "the selection was not kept (" + state_.session.status() + ")");
    }
  }

  // One frame that advances the input's clock by `seconds` (a replay's
  // fixed step, or the real interval live): the panels and views, then
  // ImGui's draw. The frame rate shown is measured from real intervals.
  // While a background command runs, the frame is the last one drawn
  // before it, with a progress indicator. False for those frames and the
  // one in which the command ended (a recorder counts the others). A
  // command asked for during the frame starts once it is drawn.
  bool frame(double seconds) {
    WorkbenchState& s = state_;
    ImGuiIO& io = ImGui::GetIO();
    const auto [width, height] = s.window.framebuffer_size();
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DeltaTime = static_cast<float>(std::max(seconds, 1e-4));
    const auto now = std::chrono::steady_clock::now();
    if (s.frames > 0) {
      const double real = std::chrono::duration<double>(now - s.last_frame).count();
      s.frame_seconds = s.frames == 1 ? real : 0.8 * s.frame_seconds + 0.2 * real;
    }
    s.last_frame = now;
    // A command running: its end is awaited for up to a frame's time (a
    // short command shows nothing), else the frame shows it running.
    const bool was_running = s.command.running();
    if (was_running) {
      if (!s.command.collect(kWaitingFrame)) {
        waiting_frame(width, height);
        return false;
      }
      s.command_status = s.session.status();
    }
    s.layout(width, height);
    s.probes.clear();  // the widgets this frame draws name themselves again
    input_.fly_keys(seconds);
    ImGui_ImplOpenGL3_NewFrame();
    scale_fonts_and_style();  // after the backend made its font texture
    ImGui::NewFrame();
    project_window();
    toolbar_panel(s);
    panorama_view(s);
    view_3d(s);
    status_panel(s);
    questions_panel(s);
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClearColor(0.11f, 0.12f, 0.14f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    ++s.frames;
    if (s.command.asked()) {
      freeze(width, height);
      s.drag = Drag::kNone;  // a drag does not go on under the command
      s.command.start();
    }
    return !was_running;
  }

  // The window as last drawn (before the buffers swap) into a PNG.
  void screenshot(const std::filesystem::path& file) const {
    const auto [width, height] = state_.window.framebuffer_size();
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

  // Where `place` is in the frame drawn last; none when it is not drawn
  // there (a widget of a panel closed, no scan shown, no 3D view).
  std::optional<std::array<double, 2>> locate(const ReplayPlace& place) const {
    const WorkbenchState& s = state_;
    std::array<double, 2> at = place.at;
    switch (place.kind) {
      case ReplayPlace::Kind::kWindow:
        break;
      case ReplayPlace::Kind::kWidget: {
        const auto found = s.probes.find(place.widget);
        if (found == s.probes.end()) return std::nullopt;
        at = {found->second[0], found->second[1]};
        break;
      }
      case ReplayPlace::Kind::kPixel: {
        if (!s.session.has_grid() || s.panorama.w <= 0.0f || s.panorama.h <= 0.0f)
          return std::nullopt;
        const ImVec2 p = s.panorama_screen(Eigen::Vector2d(at[0], at[1]));
        at = {p.x, p.y};
        break;
      }
      case ReplayPlace::Kind::kView3d:
        if (s.view3d.w <= 0.0f || s.view3d.h <= 0.0f) return std::nullopt;
        at = {s.view3d.x + at[0] * s.view3d.w, s.view3d.y + at[1] * s.view3d.h};
        break;
    }
    return std::array<double, 2>{at[0] + place.offset[0], at[1] + place.offset[1]};
  }

  // The 3D view's moving frames: how many, how many broke their point
  // budget, and their times against the target [ms].
  nlohmann::json moving_frames() const {
    const WorkbenchState& s = state_;
    std::vector<double> ms = s.moving_frame_ms;
    std::sort(ms.begin(), ms.end());
    const auto quantile = [&ms](double q) {
      return ms.empty() ? 0.0
                        : ms[static_cast<std::size_t>(q * static_cast<double>(ms.size() - 1))];
    };
    const auto within =
        std::count_if(ms.begin(), ms.end(), [&s](double t) { return t <= s.budget.target_ms(); });
    return {{"moving", s.moving_frames},
            {"over_budget", s.frames_over_budget},
            {"target_ms", s.budget.target_ms()},
            {"frame_ms_p50", quantile(0.5)},
            {"frame_ms_p95", quantile(0.95)},
            {"within_target",
             ms.empty() ? 1.0 : static_cast<double>(within) / static_cast<double>(ms.size())}};
  }

  // The centres of the named widgets, the scan shown, the status line and
  // where the views are, for tests that write replays.
  void write_layout(const std::filesystem::path& file) const {
    const WorkbenchState& s = state_;
    nlohmann::json widgets = nlohmann::json::object();
    for (const auto& [name, at] : s.probes) widgets[name] = {at[0], at[1]};
    const nlohmann::json out = {
        {"widgets", widgets},
        {"scan", s.session.scan_id()},
        {"status", s.session.status()},
        {"ui_scale", s.ui_scale},
        {"selected", s.selected},
        {"panorama",
         {{"x", s.panorama.x + s.pan[0]},
          {"y", s.panorama.y + s.pan[1]},
          {"scale", s.panorama_scale()},
          {"columns", s.session.scan().columns},
          {"rows", s.session.scan().rows}}},
        {"view3d", {s.view3d.x, s.view3d.y, s.view3d.w, s.view3d.h}},
        {"store", {{"builds", s.session.store_builds()}, {"updates", s.session.store_updates()}}},
        {"renderer", {{"opened", s.renderers_opened}, {"follows", s.renderer_follows}}},
        {"selection",
         {{"pixels", s.session.selected_pixels()}, {"scans", s.session.selected_scans()}}},
        {"frames", moving_frames()}};
    std::ofstream stream(file);
    stream << out.dump(1) << "\n";
    if (!stream.flush()) throw core::RuntimeFailure(file.string(), {}, "cannot write the layout");
  }

 private:
  // The project panel on the left: scans, objects, colour, 3D view.
  void project_window() {
    const float h = ImGui::GetIO().DisplaySize.y - state_.px(kStatusHeight);
    place_window(0, 0, state_.px(kPanelWidth), h);
    ImGui::Begin("Project", nullptr, kFixedWindow);
    scans_panel(state_);
    objects_panel(state_);
    proposals_panel(state_);
    color_panel(state_);
    view_settings_panel(state_);
    measure_panel(state_);
    ImGui::End();
  }

  // ImGui's fonts and sizes at the layout's scale: the default font
  // rasterised anew at its size (crisp, not stretched), the style's sizes
  // scaled from the default's.
  void scale_fonts_and_style() {
    if (fonts_scale_ == state_.ui_scale) return;
    fonts_scale_ = state_.ui_scale;
    ImGuiIO& io = ImGui::GetIO();
    io.Fonts->Clear();
    ImFontConfig font;  // as AddFontDefault sets it, at another size
    font.SizePixels = std::round(13.0f * fonts_scale_);
    font.OversampleH = font.OversampleV = 1;
    font.PixelSnapH = true;
    io.Fonts->AddFontDefault(&font);
    io.MouseDragThreshold = 6.0f * fonts_scale_;
    ImGui_ImplOpenGL3_DestroyFontsTexture();
    ImGui_ImplOpenGL3_CreateFontsTexture();
    ImGuiStyle style;
    ImGui::StyleColorsDark(&style);
    style.ScaleAllSizes(fonts_scale_);
    ImGui::GetStyle() = style;
  }

  // The frame just drawn, kept in a texture to show while a command runs.
  void freeze(int width, int height) {
    glBindTexture(GL_TEXTURE_2D, frozen_texture_);
    glReadBuffer(GL_BACK);
    glCopyTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, 0, 0, width, height, 0);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindTexture(GL_TEXTURE_2D, 0);
  }

  // A frame while the command runs: the frozen frame (stretched if the
  // window was resized meanwhile) and the progress indicator over it.
  // Nothing of the session is read, and ImGui's clock stands still.
  void waiting_frame(int width, int height) {
    ImGui::GetIO().DeltaTime = 1e-6f;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
    ImGui::GetBackgroundDrawList()->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(frozen_texture_)), ImVec2(0, 0),
        ImVec2(static_cast<float>(width), static_cast<float>(height)), ImVec2(0, 1), ImVec2(1, 0));
    command_progress_panel(state_);
    ImGui::Render();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  }

  WorkbenchState state_;
  WorkbenchInput input_;
  unsigned frozen_texture_ = 0;
  float fonts_scale_ = 1.0f;  // what the font atlas and style were made for
};

// What a place is called in a replay's error.
std::string describe(const ReplayPlace& place) {
  switch (place.kind) {
    case ReplayPlace::Kind::kWidget:
      return "the widget \"" + place.widget + "\" is not drawn";
    case ReplayPlace::Kind::kPixel:
      return "no scan's panoramic view is shown for the pixel";
    case ReplayPlace::Kind::kView3d:
      return "the 3D view is not shown";
    case ReplayPlace::Kind::kWindow:
      break;
  }
  return "the place is not in the window";
}

// Frames until the workbench settles (Workbench::settled), at most a
// minute of them: a store built in the background, the 3D view refined.
void settle(Workbench& bench, render::WindowDevice& window) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!bench.settled() && std::chrono::steady_clock::now() < give_up) {
    window.swap_buffers();
    bench.frame(kReplayFrameSeconds);
  }
}

// Feeds the events, a frame each, to `input` (the workbench's, or a
// recorder in front of it), then takes the screenshot and layout asked for.
// The places a pointer event names are found in the frame before it is
// fed (a drag's ends when it starts). Throws core::InputError naming the
// file and the event when a place is not drawn; the events before it have
// acted, as a user's would have, and the journal keeps their commands.
void replay(Workbench& bench, render::WindowDevice& window, const WorkbenchOptions& options,
            const std::vector<ReplayEvent>& events, render::WindowInput& input,
            ReplayRecorder* recorder) {
  bench.frame(kReplayFrameSeconds);  // the first frame lays the panels out
  window.swap_buffers();
  std::optional<std::size_t> located_entry;
  std::array<double, 2> from{}, to{};
  for (const ReplayEvent& e : events) {
    ReplayEvent fed = e;
    if (e.kind == ReplayEvent::Kind::kMove) {
      if (located_entry != e.entry) {
        const auto find = [&](const ReplayPlace& place) {
          const std::optional<std::array<double, 2>> at = bench.locate(place);
          if (!at) {
            const acquisition::JsonPlace where{options.replay.string(),
                                               "events[" + std::to_string(e.entry) + "]"};
            where.refuse(describe(place) + " in the frame this event is fed to");
          }
          return *at;
        };
        from = find(e.from);
        to = find(e.to);
        located_entry = e.entry;
      }
      fed.x = from[0] + e.t * (to[0] - from[0]);
      fed.y = from[1] + e.t * (to[1] - from[1]);
    }
    feed(input, fed);
    // A wait's frames one after the other; any other event takes one.
    const int frames = e.kind == ReplayEvent::Kind::kWait ? e.frames : 1;
    for (int f = 0; f < frames; ++f) {
      bench.frame(kReplayFrameSeconds);
      // The next event waits for the command this one started, as a user
      // does: the window takes no presses meanwhile.
      while (bench.busy()) {
        window.swap_buffers();
        bench.frame(kReplayFrameSeconds);
      }
      if (recorder) recorder->next_frame();
      if (e.kind == ReplayEvent::Kind::kScreenshot) {
        settle(bench, window);
        bench.screenshot(e.file);
      }
      if (e.kind == ReplayEvent::Kind::kLayout) bench.write_layout(e.file);
      window.swap_buffers();
    }
  }
  do {
    bench.frame(kReplayFrameSeconds);
  } while (bench.busy());
  if (!options.screenshot.empty()) {
    settle(bench, window);
    bench.screenshot(options.screenshot);
  }
  if (!options.layout.empty()) bench.write_layout(options.layout);
}

// Frames until the window closes (or, with a screenshot asked for, until
// the opened project is drawn).
void live(Workbench& bench, render::WindowDevice& window, const WorkbenchOptions& options,
          ReplayRecorder* recorder) {
  auto last = std::chrono::steady_clock::now();
  bool layout_written = false;
  while (!window.close_requested()) {
    window.poll_events();
    const auto now = std::chrono::steady_clock::now();
    const bool drew_panels = bench.frame(std::chrono::duration<double>(now - last).count());
    if (recorder && drew_panels) recorder->next_frame();
    last = now;
    if (!layout_written && !options.layout.empty() && !bench.busy()) {
      bench.write_layout(options.layout);
      layout_written = true;
    }
    if (!options.screenshot.empty()) {
      settle(bench, window);
      bench.screenshot(options.screenshot);
      return;  // a screenshot of the opened project is all that was asked for
    }
    window.swap_buffers();
  }
  // Closed while a command runs: the window shows it to its end.
  while (bench.busy()) {
    window.poll_events();
    bench.frame(0.0);
    window.swap_buffers();
  }
}

}  // namespace

void run_workbench(const WorkbenchOptions& options) {
  // Bad input first, before a window opens.
  const std::vector<ReplayEvent> events =
      options.replay.empty() ? std::vector<ReplayEvent>{} : read_replay(options.replay);
  render::WindowDevice window(options.width, options.height, "scanbench workbench");
  const ImGuiScope imgui;
  Workbench bench(options, window);
  std::optional<ReplayRecorder> recorder;
  if (!options.record.empty()) {
    recorder.emplace(bench.input(), options.record,
                     [&bench] { return bench.input().takes_presses(); });
  }
  render::WindowInput& input =
      recorder ? static_cast<render::WindowInput&>(*recorder) : bench.input();
  window.set_input(&input);
  struct Detach {
    render::WindowDevice& window;
    ~Detach() { window.set_input(nullptr); }
  } detach{window};
  try {
    if (options.replay.empty()) {
      live(bench, window, options, recorder ? &*recorder : nullptr);
    } else {
      replay(bench, window, options, events, input, recorder ? &*recorder : nullptr);
    }
  } catch (...) {
    if (recorder) recorder->save();  // a session that failed is the one to send
    throw;
  }
  if (recorder) recorder->save();
  bench.end_session();
}

}  // namespace scanbench::app::workbench

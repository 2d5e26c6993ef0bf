// scanbench render PROJECT --view VIEW.json -o OUT.png [--mode points|splats|blended]
//                  [--kernel disk|gaussian|cosine] [--color MODE] [--budget N] [--json]
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "acquisition/camera_view.hpp"
#include "acquisition/formats/picture_file.hpp"
#include "app/commands.hpp"
#include "modeling/export_command.hpp"
#include "render/device.hpp"
#include "render/frame_budget.hpp"
#include "render/lod_renderer.hpp"

namespace scanbench::app {
namespace {

struct RenderOptions {
  std::string project;
  std::string view;
  std::string path;          // a camera path instead of a view
  double target_ms = 100.0;  // a path's frame-time target
  std::string output;
  render::RenderSettings settings;
  bool culling = true;
  bool json = false;
  bool force = false;
};

nlohmann::json frame_json(const render::LodFrameResult& frame,
                          const render::LodFrameResult& first) {
  const render::LodFramePlan& plan = frame.plan;
  return {{"points", plan.points},
          {"points_submitted", plan.submitted},
          {"culled_frustum", plan.culled_frustum},
          {"culled_clip", plan.culled_clip},
          {"culled_budget", plan.stopped_by_budget},
          {"nodes_drawn", plan.draws.size()},
          {"frame_ms", frame.frame_ms},
          {"first_frame_ms", first.frame_ms}};
}

// What a render needs, whatever it draws: the picture's file checked, the
// project's current store (built when missing or out of date), a device,
// and the renderer showing the project's objects and corrections.
struct RenderSession {
  store::Project project;
  double build_seconds = 0.0;
  std::filesystem::path store;
  std::unique_ptr<render::RenderDevice> device;
  std::unique_ptr<render::LodRenderer> renderer;
};

RenderSession open_render_session(RenderOptions& options) {
  if (std::filesystem::path(options.output).extension() != ".png")
    throw CLI::ValidationError("-o", "must name a .png file");
  RenderSession session{store::Project::open_for_reading(options.project), 0.0, {}, {}, {}};
  const std::filesystem::path outputs[] = {options.output};
  modeling::refuse_to_replace_inputs(session.project, outputs, options.force);
  session.store = current_lod_store(session.project, session.build_seconds);
  if (!options.culling) {
    options.settings.culling.frustum = false;
    options.settings.culling.backface = false;
    options.settings.culling.level_of_detail = false;
  }
  session.device = render::make_headless_device();
  session.renderer =
      std::make_unique<render::LodRenderer>(session.store, render::LodRendererLimits{});
  session.renderer->show_project_state(session.project);
  return session;
}

void write_picture(const render::LodRenderer& renderer, const std::string& output) {
  const render::RenderedImage image = renderer.read_image();
  acquisition::write_rgb_picture(output, image.width, image.height, image.rgb());
}

nlohmann::json settings_json(const RenderOptions& options, const RenderSession& session) {
  return {{"store", session.store.string()},
          {"store_build_seconds", session.build_seconds},
          {"nodes", session.renderer->hierarchy().nodes.size()},
          {"mode", render::draw_mode_name(options.settings.mode)},
          {"kernel", render::kernel_name(options.settings.kernel)},
          {"color", render::color_mode_name(options.settings.color)},
          {"device", session.device->describe()},
          {"output", options.output}};
}

void render_view(RenderOptions& options) {
  const acquisition::CameraView camera = acquisition::read_camera_view(options.view);
  RenderSession session = open_render_session(options);
  render::LodRenderer& renderer = *session.renderer;
  const render::RenderView view = render::make_render_view(camera, renderer.header().origin);
  // The first frame loads the nodes the view wants and pays for the driver
  // compiling the shaders' variants; the second is what a frame costs once
  // they are on the device.
  const render::LodFrameResult first = renderer.draw_complete(view, options.settings);
  const render::LodFrameResult frame = renderer.draw_complete(view, options.settings);
  write_picture(renderer, options.output);
  if (options.json) {
    nlohmann::json out = frame_json(frame, first);
    out.update(settings_json(options, session));
    out["device_bytes"] = renderer.device_bytes();
    out["width"] = camera.width;
    out["height"] = camera.height;
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print("rendered {} of {} points ({} nodes) in {:.1f} ms to {} ({} × {}, {})\n",
             frame.plan.submitted, frame.plan.points, frame.plan.draws.size(), frame.frame_ms,
             options.output, camera.width, camera.height,
             render::draw_mode_name(options.settings.mode));
  fmt::print("  left out: {} outside the frustum, {} clipped, {} by the budget\n",
             frame.plan.culled_frustum, frame.plan.culled_clip, frame.plan.stopped_by_budget);
}

double percentile(std::vector<double> values, double p) {
  const auto at = static_cast<std::size_t>(p * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(at), values.end());
  return values[at];
}

// A fly-through: every frame of the path streamed as a moving camera's,
// the budget keeping frames near the target; then, the camera still at the
// last pose, frames until the picture is complete.
void render_path(RenderOptions& options) {
  const std::vector<acquisition::CameraView> cameras = acquisition::read_camera_path(options.path);
  const auto start = std::chrono::steady_clock::now();
  const auto since = [](std::chrono::steady_clock::time_point from) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - from).count();
  };
  RenderSession session = open_render_session(options);
  render::LodRenderer& renderer = *session.renderer;
  const Eigen::Vector3d origin = renderer.header().origin;
  render::FrameBudget budget(options.target_ms);
  std::vector<double> frame_ms, points, gpu_ms, plan_ms, upload_ms, scales;
  double first_frame_s = -1.0;
  render::RenderSettings settings = options.settings;
  for (const acquisition::CameraView& camera : cameras) {
    settings.culling.budget = budget.next(true);
    scales.push_back(budget.scale(true));
    const render::LodFrameResult frame = renderer.draw(
        render::make_render_view(render::at_scale(camera, scales.back()), origin), settings);
    budget.record(frame.frame_ms, frame.plan.submitted);
    frame_ms.push_back(frame.frame_ms);
    gpu_ms.push_back(frame.gpu_ms);
    plan_ms.push_back(frame.plan_ms);
    upload_ms.push_back(frame.upload_ms);
    points.push_back(static_cast<double>(frame.plan.submitted));
    if (first_frame_s < 0.0 && frame.plan.submitted > 0) first_frame_s = since(start);
  }
  const auto still = std::chrono::steady_clock::now();
  settings.culling.budget = options.settings.culling.budget;
  const render::RenderView last = render::make_render_view(cameras.back(), origin);
  std::size_t refining_frames = 0;
  // As the workbench refines a still view: each frame waits up to 250 ms
  // for the nodes being read.
  while (!renderer.draw(last, settings, std::chrono::milliseconds(250)).complete())
    ++refining_frames;
  const double converge_seconds = since(still);
  write_picture(renderer, options.output);
  nlohmann::json out = settings_json(options, session);
  out.update({{"frames", cameras.size()},
              {"target_ms", options.target_ms},
              {"first_frame_ms", 1000.0 * first_frame_s},
              {"frame_ms_p50", percentile(frame_ms, 0.5)},
              {"frame_ms_p95", percentile(frame_ms, 0.95)},
              {"frame_ms_max", *std::max_element(frame_ms.begin(), frame_ms.end())},
              {"points_per_frame_p50", percentile(points, 0.5)},
              {"moving_scale_p50", percentile(scales, 0.5)},
              {"moving_scale_min", *std::min_element(scales.begin(), scales.end())},
              {"gpu_ms_p50", percentile(gpu_ms, 0.5)},
              {"plan_ms_p50", percentile(plan_ms, 0.5)},
              {"upload_ms_p50", percentile(upload_ms, 0.5)},
              {"converge_seconds", converge_seconds},
              {"converge_frames", refining_frames + 1},
              {"gpu_cache_bytes_peak", renderer.device_peak_bytes()},
              {"memory_cache_bytes_peak", renderer.memory_peak_bytes()},
              {"width", cameras.back().width},
              {"height", cameras.back().height}});
  if (options.json) {
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print(
      "{} frames at {} × {}: {:.0f} ms median, {:.0f} ms 95th percentile (target {:.0f} ms), "
      "{:.0f} points a frame; the last view complete {:.2f} s after the camera stopped, in {}\n",
      cameras.size(), cameras.back().width, cameras.back().height,
      out["frame_ms_p50"].get<double>(), out["frame_ms_p95"].get<double>(), options.target_ms,
      out["points_per_frame_p50"].get<double>(), converge_seconds, options.output);
}

void run_render(RenderOptions& options) {
  if (options.view.empty() && options.path.empty())
    throw CLI::ValidationError("--view", "a camera view file or --path is required");
  if (options.path.empty()) {
    render_view(options);
  } else {
    render_path(options);
  }
}

template <typename Enum>
std::map<std::string, Enum> names_of(std::string_view (*name)(Enum), int count) {
  std::map<std::string, Enum> names;
  for (int k = 0; k < count; ++k)
    names.emplace(std::string(name(static_cast<Enum>(k))), static_cast<Enum>(k));
  return names;
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto options = std::make_shared<RenderOptions>();
  render::RenderSettings& s = options->settings;
  s.background = {170, 200, 235};  // the sky of `scanbench simulate --render-view`
  CLI::App* command = app.add_subcommand(
      "render",
      "Render the project's merged model as splats (headless, OpenGL 4.5 through EGL) from a "
      "camera view file, the format of `scanbench simulate --render-view`: kept points, hidden "
      "objects left out, drawn from the project's level-of-detail store (built first when it is "
      "missing or out of date, as `scanbench lod` does).");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  CLI::Option* view = command->add_option("--view", options->view, "Camera view file (JSON)")
                          ->check(CLI::ExistingFile);
  CLI::Option* path =
      command
          ->add_option("--path", options->path,
                       "Camera path file (JSON: a view file's size and angle, and \"frames\": "
                       "poses): a fly-through drawn as the camera moves, then refined at its last "
                       "pose; -o gets the last picture")
          ->check(CLI::ExistingFile)
          ->excludes(view);
  view->excludes(path);
  command
      ->add_option("--target-ms", options->target_ms,
                   "With --path: the frame time the point budget keeps to while moving [ms]")
      ->check(CLI::Range(1.0, 10000.0))
      ->capture_default_str();
  command->add_option("-o,--output", options->output, "Picture (.png)")->required();
  command->add_flag("--force", options->force,
                    "Replace the picture when it exists (never the project or its sources)");
  command->add_option("--mode", s.mode, "points, splats or blended")
      ->transform(one_of(names_of(&render::draw_mode_name, 3)))
      ->default_str("blended");
  command->add_option("--kernel", s.kernel, "disk, gaussian or cosine")
      ->transform(one_of(names_of(&render::kernel_name, 3)))
      ->default_str("gaussian");
  command->add_option("--color", s.color, "color, intensity, height, normal or object")
      ->transform(one_of(names_of(&render::color_mode_name, 5)))
      ->default_str("color");
  command->add_option("--budget", s.culling.budget, "Points per frame (0: no budget)")
      ->capture_default_str();
  command->add_option("--splat-scale", s.splat_scale, "Splat radii × the sample's cell")
      ->check(CLI::Range(0.1, 10.0))
      ->capture_default_str();
  command
      ->add_option("--fill", s.fill_reach_px,
                   "Fill holes ringed by splats within this many pixels (0: off)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  command->add_flag("--lighting", s.lighting, "Shade by the normals, light at the eye");
  command->add_flag("--eye-dome", s.eye_dome, "Eye-dome lighting (for scans without colour)");
  command->add_flag("!--no-culling", options->culling,
                    "Draw every point: no frustum, backface or level-of-detail culling");
  command->add_flag("--json", options->json, "Print the frame's figures as JSON");
  command->callback([options] { run_render(*options); });
}

}  // namespace scanbench::app

// scanbench render PROJECT --view VIEW.json -o OUT.png [--mode points|splats|blended]
//                  [--kernel disk|gaussian|cosine] [--color MODE] [--budget N] [--json]
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "acquisition/camera_view.hpp"
#include "acquisition/formats/picture_file.hpp"
#include "app/commands.hpp"
#include "core/timing.hpp"
#include "modeling/export_command.hpp"
#include "render/device.hpp"
#include "render/render_model.hpp"
#include "render/splat_renderer.hpp"

namespace scanbench::app {
namespace {

struct RenderOptions {
  std::string project;
  std::string view;
  std::string output;
  render::RenderSettings settings;
  bool all_points = false;
  bool culling = true;
  bool json = false;
  bool force = false;
};

nlohmann::json plan_json(const render::FrameResult& frame, const render::FrameResult& first) {
  const render::FramePlan& plan = frame.plan;
  return {{"points", plan.points},
          {"points_submitted", plan.submitted},
          {"culled_frustum", plan.culled_frustum},
          {"culled_backface", plan.culled_backface},
          {"culled_budget", plan.culled_budget},
          {"hidden", plan.hidden},
          {"tiles_drawn", plan.tiles_drawn},
          {"frame_ms", frame.frame_ms},
          {"first_frame_ms", first.frame_ms}};
}

void run_render(RenderOptions& options) {
  if (std::filesystem::path(options.output).extension() != ".png")
    throw CLI::ValidationError("-o", "must name a .png file");
  const acquisition::CameraView camera = acquisition::read_camera_view(options.view);
  const store::Project project = store::Project::open_for_reading(options.project);
  const std::filesystem::path outputs[] = {options.output};
  modeling::refuse_to_replace_inputs(project, outputs, options.force);
  const auto start = std::chrono::steady_clock::now();
  render::RenderModelSettings model_settings;
  model_settings.merged_only = !options.all_points;
  const render::RenderModel model = render::build_render_model(project, model_settings);
  const double build_seconds = core::seconds_since(start);

  if (!options.culling) {
    options.settings.culling.frustum = false;
    options.settings.culling.backface = false;
    options.settings.culling.level_of_detail = false;
  }
  const std::unique_ptr<render::RenderDevice> device = render::make_headless_device();
  render::SplatRenderer renderer(model);
  const render::RenderView view = render::make_render_view(camera, model.origin);
  // The first frame pays for the driver compiling the shaders' variants;
  // the second is what every later frame costs.
  const render::FrameResult first = renderer.draw(view, options.settings);
  const render::FrameResult frame = renderer.draw(view, options.settings);
  const render::RenderedImage image = renderer.read_image();
  std::vector<std::uint8_t> rgb(3 * static_cast<std::size_t>(image.width) * image.height);
  for (std::size_t i = 0; i < rgb.size() / 3; ++i) {
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = image.rgba[4 * i + c];
  }
  acquisition::write_rgb_picture(options.output, image.width, image.height, rgb);

  if (options.json) {
    nlohmann::json out = plan_json(frame, first);
    out["tiles"] = model.tiles.size();
    out["build_seconds"] = build_seconds;
    out["mode"] = render::draw_mode_name(options.settings.mode);
    out["kernel"] = render::kernel_name(options.settings.kernel);
    out["color"] = render::color_mode_name(options.settings.color);
    out["width"] = image.width;
    out["height"] = image.height;
    out["device"] = device->describe();
    out["output"] = options.output;
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print("rendered {} of {} points ({} tiles) in {:.1f} ms to {} ({} × {}, {})\n",
             frame.plan.submitted, frame.plan.points, frame.plan.tiles_drawn, frame.frame_ms,
             options.output, image.width, image.height,
             render::draw_mode_name(options.settings.mode));
  fmt::print(
      "  culled: {} by the frustum, {} facing away, {} by level of detail and budget; {} "
      "hidden\n",
      frame.plan.culled_frustum, frame.plan.culled_backface, frame.plan.culled_budget,
      frame.plan.hidden);
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
      "objects left out, culled through the object tree.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--view", options->view, "Camera view file (JSON)")
      ->required()
      ->check(CLI::ExistingFile);
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
  command->add_flag("--all-points", options->all_points, "Also the points the merge dropped");
  command->add_flag("--json", options->json, "Print the frame's figures as JSON");
  command->callback([options] { run_render(*options); });
}

}  // namespace scanbench::app

// The protocol: the campus at seed 1, 4 scans at their true poses, lit as
// the truth pictures are, their geometry and merge; the level-of-detail
// store of the merged points, drawn complete. For three
// cameras ("closeup": Keller Hall's west façade from 9 m, scanned from
// 20–35 m; "street": eye height across the quad; "overview": from 90 m up
// and away) the simulator ray-casts the truth picture (reference lighting,
// no noise), and each mode renders the same camera. Pixels count where the
// truth's surface was sampled by some scan (sampled_mask): a roof no scanner
// saw, or ground so far off that the scans' rows are more than 8 footprints
// apart, is not a hole of the renderer. Frame times: the street view, blended, the median
// of 5 frames after a warm-up, culling (frustum, facing away, level of
// detail) on and off.
#include "bench/bench_render.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>

#include "acquisition/camera_view.hpp"
#include "acquisition/formats/picture_file.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/truth_view.hpp"
#include "acquisition/spherical_grid.hpp"
#include "bench/campus_views.hpp"
#include "bench/image_metrics.hpp"
#include "bench/scratch_folder.hpp"
#include "bench/simulated_site.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/store/layer_store.hpp"
#include "modeling/store/typed_layers.hpp"
#include "registration/merge.hpp"
#include "registration/prepared_scan.hpp"
#include "render/device.hpp"
#include "render/lod_renderer.hpp"

namespace scanbench::bench {

namespace {

namespace sim = acquisition::sim;

// The campaign in a project (true poses, geometry, the merge's keep masks)
// and its level-of-detail store: the path `scanbench render` takes.
std::filesystem::path campus_store(const SimulatedSite& site, const ScratchFolder& scratch) {
  const std::filesystem::path file = scratch.path() / "render.sbproj";
  store_site_project(site, file);
  core::Progress quiet;
  return lod::build_lod(store::Project::open(file), {}, quiet).store;
}

struct ViewFigures {
  nlohmann::json modes = nlohmann::json::object();
  double blended_minus_points_db = 0.0;
};

ViewFigures measure_view(render::LodRenderer& renderer, const sim::Scene& scene,
                         const NamedView& view, const SimulatedSite& site,
                         const std::filesystem::path& pictures) {
  const sim::TruthImage truth = sim::render_truth_view(scene, view.camera);
  const std::vector<std::uint8_t> mask = sampled_mask(truth, view.camera, site);
  const auto picture = [&](const std::string& what, const std::vector<std::uint8_t>& rgb) {
    if (pictures.empty()) return;
    std::filesystem::create_directories(pictures);
    acquisition::write_rgb_picture(pictures / (std::string(view.name) + "_" + what + ".png"),
                                   truth.width, truth.height, rgb);
  };
  picture("truth", truth.rgb);
  const render::RenderView camera = render::make_render_view(view.camera, renderer.header().origin);
  ViewFigures out;
  double points_db = 0.0;
  for (const render::DrawMode mode :
       {render::DrawMode::kPoints, render::DrawMode::kSplats, render::DrawMode::kBlended}) {
    render::RenderSettings settings;
    settings.mode = mode;
    settings.background = {sim::kSkyRgb[0], sim::kSkyRgb[1], sim::kSkyRgb[2]};
    const render::LodFrameResult frame = renderer.draw_complete(camera, settings);
    const render::RenderedImage image = renderer.read_image();
    const std::vector<std::uint8_t> rgb = image.rgb(), covered = image.coverage();
    picture(std::string(render::draw_mode_name(mode)), rgb);
    if (mode == render::DrawMode::kBlended) {  // the holes, magenta on the truth
      std::vector<std::uint8_t> holes = truth.rgb;
      for (std::size_t i = 0; i < mask.size(); ++i) {
        if (mask[i] && !covered[i])
          holes[3 * i] = 255, holes[3 * i + 1] = 0, holes[3 * i + 2] = 255;
      }
      picture("holes", holes);
    }
    const PictureComparison c =
        compare_pictures(truth.width, truth.height, rgb, truth.rgb, covered, mask);
    out.modes[std::string(render::draw_mode_name(mode))] = {
        {"psnr_db", c.psnr_db},
        {"ssim", c.ssim},
        {"hole_fraction", c.hole_fraction},
        {"points_submitted", frame.plan.submitted},
        {"frame_ms", frame.frame_ms}};
    out.modes["sampled_pixels"] = c.pixels;
    if (mode == render::DrawMode::kBlended) {  // what the splats alone leave open
      settings.fill_reach_px = 0;
      renderer.draw_complete(camera, settings);
      const render::RenderedImage unfilled = renderer.read_image();
      std::size_t open = 0;
      for (std::size_t i = 0; i < mask.size(); ++i)
        open += mask[i] && unfilled.rgba[4 * i + 3] == 0;
      out.modes["blended"]["hole_fraction_unfilled"] =
          c.pixels == 0 ? 0.0 : static_cast<double>(open) / static_cast<double>(c.pixels);
    }
    if (mode == render::DrawMode::kPoints) points_db = c.psnr_db;
    if (mode == render::DrawMode::kBlended) out.blended_minus_points_db = c.psnr_db - points_db;
  }
  return out;
}

// The median frame time of `frames` frames after one to warm up (and to
// load what the view wants).
double median_frame_ms(render::LodRenderer& renderer, const render::RenderView& view,
                       const render::RenderSettings& settings, int frames,
                       render::LodFramePlan* plan) {
  *plan = renderer.draw_complete(view, settings).plan;
  std::vector<double> times;
  for (int k = 0; k < frames; ++k) times.push_back(renderer.draw_complete(view, settings).frame_ms);
  std::nth_element(times.begin(), times.begin() + frames / 2, times.end());
  return times[static_cast<std::size_t>(frames / 2)];
}

}  // namespace

// Longer than 60 lines, but flat: the suite's cameras and measurements in
// order, sharing the simulated site and its store.
nlohmann::json run_render_bench(const BenchOptions& options) {
  sim::ScannerModel scanner;
  if (options.smoke) {
    scanner.columns = 900;
    scanner.rows = 225;
  }
  const int scan_count = options.smoke ? 2 : 4;
  const int width = options.smoke ? 240 : 960, height = options.smoke ? 135 : 540;
  // The scans lit as the truth pictures are: what differs is the renderer's
  // doing, not the campaign's exposures (the colour bench measures those).
  const SimulatedSite site = simulate_site("campus", scanner, scan_count, SiteLighting::kReference);
  const sim::Site scene_site = sim::make_site("campus", kSiteSeed, scan_count);
  const ScratchFolder scratch("render");
  const auto build_start = std::chrono::steady_clock::now();
  const std::filesystem::path store = campus_store(site, scratch);
  const double build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();

  const std::unique_ptr<render::RenderDevice> device = render::make_headless_device();
  render::LodRenderer renderer(store, {});
  nlohmann::json views = nlohmann::json::object();
  double closeup_gain_db = 0.0, worst_hole = 0.0;
  for (const NamedView& view : campus_views(width, height)) {
    const ViewFigures figures =
        measure_view(renderer, scene_site.scene, view, site, options.pictures);
    views[view.name] = figures.modes;
    worst_hole = std::max(worst_hole, figures.modes["blended"]["hole_fraction"].get<double>());
    if (std::string(view.name) == "closeup") closeup_gain_db = figures.blended_minus_points_db;
  }

  const NamedView street = campus_views(width, height)[1];
  const render::RenderView street_view =
      render::make_render_view(street.camera, renderer.header().origin);
  render::RenderSettings culled, unculled;
  unculled.culling.frustum = unculled.culling.backface = unculled.culling.level_of_detail = false;
  const int frames = options.smoke ? 1 : 5;
  render::LodFramePlan plan_on, plan_off;
  const double on_ms = median_frame_ms(renderer, street_view, culled, frames, &plan_on);
  const double off_ms = median_frame_ms(renderer, street_view, unculled, frames, &plan_off);
  const double culled_share =
      1.0 - static_cast<double>(plan_on.submitted) / static_cast<double>(plan_on.points);

  return {{"suite", "render"},
          {"site", "campus"},
          {"scans", scan_count},
          {"points", renderer.header().points},
          {"nodes", renderer.hierarchy().nodes.size()},
          {"store_build_seconds", build_seconds},
          {"width", width},
          {"height", height},
          {"device", device->describe()},
          {"views", views},
          {"frame_ms_culling_on", on_ms},
          {"frame_ms_culling_off", off_ms},
          {"culling_speedup", off_ms / on_ms},
          {"culled_share", culled_share},
          {"street_culled",
           {{"frustum", plan_on.culled_frustum},
            {"level_of_detail",
             plan_on.points - plan_on.submitted - plan_on.culled_frustum - plan_on.culled_clip},
            {"submitted", plan_on.submitted}}},
          {"closeup_blended_minus_points_db", closeup_gain_db},
          {"blended_hole_fraction_worst", worst_hole},
          {"goals",
           {{"blended_hole_fraction_at_most_0_005", worst_hole <= 0.005},
            {"closeup_blended_beats_points_by_6_db", closeup_gain_db >= 6.0},
            {"culling_at_least_halves_street_frame_time", off_ms >= 2.0 * on_ms}}}};
}

}  // namespace scanbench::bench

#include "bench/bench_lod.hpp"

#include <chrono>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>

#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "bench/campus_views.hpp"
#include "bench/child_process.hpp"
#include "bench/image_metrics.hpp"
#include "bench/scratch_folder.hpp"
#include "bench/simulated_site.hpp"
#include "modeling/lod/lod_store.hpp"
#include "render/device.hpp"
#include "render/lod_renderer.hpp"

namespace scanbench::bench {
namespace {

// `scanbench lod` on `project` with `threads` (0: every core), its JSON
// with the process's wall time and peak memory.
nlohmann::json timed_build(const std::filesystem::path& project, int threads,
                           const std::filesystem::path& dir) {
  const std::string stage = "lod_" + std::to_string(threads);
  const ChildRun run = run_scanbench(
      stage, {"lod", project.string(), "--json", "--threads", std::to_string(threads)}, dir);
  if (run.exit_code != 0) {
    throw std::runtime_error("bench lod: scanbench lod exited with " +
                             std::to_string(run.exit_code) + ": " + run.err);
  }
  nlohmann::json built = nlohmann::json::parse(run.out);
  built["process_seconds"] = run.seconds;
  built["peak_rss_bytes"] = run.peak_rss_bytes;
  return built;
}

namespace sim = acquisition::sim;

// Each view as the streaming renderer draws it once the camera stops,
// from cold caches (a renderer just opened): the frames until the picture
// is complete, and that picture against the truth and against the full
// picture (every point of the store drawn, no level of detail).
nlohmann::json measure_views(const std::filesystem::path& project, const SimulatedSite& site,
                             int width, int height) {
  const sim::Site scene_site =
      sim::make_site("campus", kSiteSeed, static_cast<int>(site.scans.size()));
  const std::unique_ptr<render::RenderDevice> device = render::make_headless_device();
  const std::filesystem::path store = lod::LodStore::path_for(project);
  render::LodRenderer full(store, {});
  render::RenderSettings settings;
  settings.background = {sim::kSkyRgb[0], sim::kSkyRgb[1], sim::kSkyRgb[2]};
  render::RenderSettings every_point = settings;
  every_point.culling.level_of_detail = false;
  nlohmann::json views = nlohmann::json::object();
  for (const NamedView& view : campus_views(width, height)) {
    const sim::TruthImage truth = sim::render_truth_view(scene_site.scene, view.camera);
    const std::vector<std::uint8_t> mask = sampled_mask(truth, view.camera, site);
    full.draw_complete(render::make_render_view(view.camera, full.header().origin), every_point);
    const render::RenderedImage full_image = full.read_image();
    render::LodRenderer streaming(store, {});
    const render::RenderView camera =
        render::make_render_view(view.camera, streaming.header().origin);
    const auto start = std::chrono::steady_clock::now();
    std::size_t frames = 1;
    // As the workbench refines a still view: each frame waits up to 250 ms
    // for the nodes being read.
    while (!streaming.draw(camera, settings, std::chrono::milliseconds(250)).complete()) ++frames;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const render::RenderedImage image = streaming.read_image();
    const auto against = [&](const std::vector<std::uint8_t>& rgb,
                             const std::vector<std::uint8_t>& reference,
                             const std::vector<std::uint8_t>& where) {
      return compare_pictures(width, height, rgb, reference, image.coverage(), where).psnr_db;
    };
    const std::vector<std::uint8_t> full_covered = full_image.coverage();
    views[view.name] = {
        {"converged_psnr_db", against(image.rgb(), truth.rgb, mask)},
        {"full_renderer_psnr_db",
         compare_pictures(width, height, full_image.rgb(), truth.rgb, full_covered, mask).psnr_db},
        {"against_full_renderer_psnr_db", against(image.rgb(), full_image.rgb(), full_covered)},
        {"converge_seconds", seconds},
        {"converge_frames", frames}};
  }
  return views;
}

// A fly-through of `frames` frames: along the street at eye height, then
// up and round to the overview's camera.
void write_camera_path(const std::filesystem::path& file, int frames, int width, int height) {
  nlohmann::json poses = nlohmann::json::array();
  const Eigen::Vector3d walk_from(-22.0, -2.0, 1.7), walk_to(12.0, 5.0, 1.7);
  const Eigen::Vector3d rise_to(-55.0, -60.0, 55.0);
  for (int k = 0; k < frames; ++k) {
    const double t = static_cast<double>(k) / std::max(1, frames - 1);
    Eigen::Vector3d position, target;
    if (t < 0.5) {
      position = walk_from + 2.0 * t * (walk_to - walk_from);
      target = position + 30.0 * (walk_to - walk_from).normalized() + Eigen::Vector3d(0, 0, 1);
    } else {
      const double u = 2.0 * (t - 0.5);
      position = walk_to + u * (rise_to - walk_to);
      target = (1.0 - u) * (walk_to + 30.0 * (walk_to - walk_from).normalized());
    }
    poses.push_back({{"position", {position.x(), position.y(), position.z()}},
                     {"look_at", {target.x(), target.y(), target.z()}}});
  }
  std::ofstream(file) << nlohmann::json{
      {"width", width}, {"height", height}, {"vertical_fov_deg", 60.0}, {"frames", poses}};
}

// `scanbench render --path` in a process of its own: its JSON, with its
// peak memory.
nlohmann::json measure_path(const std::filesystem::path& project, const std::filesystem::path& dir,
                            int frames, int width, int height) {
  const std::filesystem::path path = dir / "path.json";
  write_camera_path(path, frames, width, height);
  const ChildRun run =
      run_scanbench("render_path",
                    {"render", project.string(), "--path", path.string(), "--target-ms", "100",
                     "-o", (dir / "path_last.png").string(), "--json"},
                    dir);
  if (run.exit_code != 0) {
    throw std::runtime_error("bench lod: scanbench render --path exited with " +
                             std::to_string(run.exit_code) + ": " + run.err);
  }
  nlohmann::json out = nlohmann::json::parse(run.out);
  out["peak_rss_bytes"] = run.peak_rss_bytes;
  return out;
}

}  // namespace

nlohmann::json run_lod_bench(const BenchOptions& options) {
  acquisition::sim::ScannerModel scanner;
  if (options.smoke) {
    scanner.columns = 900;
    scanner.rows = 225;
  }
  const SimulatedSite site =
      simulate_site("campus", scanner, options.smoke ? 2 : 4, SiteLighting::kReference);
  const ScratchFolder scratch("lod");
  const std::filesystem::path project = scratch.path() / "campus.sbproj";
  store_site_project(site, project);

  const nlohmann::json all = timed_build(project, 0, scratch.path());
  const nlohmann::json one = timed_build(project, 1, scratch.path());
  const double points = all["points"].get<double>();
  const int threads = all["threads"].get<int>();
  const double seconds = all["seconds"].get<double>();
  nlohmann::json out;
  out["suite"] = "lod";
  out["points"] = all["points"];
  out["nodes"] = all["nodes"];
  out["store_bytes"] = all["store_bytes"];
  out["phase_seconds"] = all["phase_seconds"];
  out["threads"] = threads;
  out["build_points_per_second"] = points / seconds;
  out["build_points_per_second_per_thread"] = points / seconds / threads;
  out["build_peak_rss_bytes"] = all["peak_rss_bytes"];
  out["full_rebuild_seconds"] = seconds;
  out["one_thread"] = {{"build_points_per_second", points / one["seconds"].get<double>()},
                       {"build_peak_rss_bytes", one["peak_rss_bytes"]},
                       {"seconds", one["seconds"]},
                       {"phase_seconds", one["phase_seconds"]}};
  const int width = options.smoke ? 240 : 960, height = options.smoke ? 135 : 540;
  const nlohmann::json path =
      measure_path(project, scratch.path(), options.smoke ? 30 : 300, width, height);
  for (const char* field : {"first_frame_ms", "frame_ms_p50", "frame_ms_p95",
                            "points_per_frame_p50", "gpu_cache_bytes_peak"}) {
    out[field] = path[field];
  }
  out["render_peak_rss_bytes"] = path["peak_rss_bytes"];
  out["path"] = {{"frames", path["frames"]},
                 {"target_ms", path["target_ms"]},
                 {"frame_ms_max", path["frame_ms_max"]},
                 {"converge_seconds", path["converge_seconds"]},
                 {"memory_cache_bytes_peak", path["memory_cache_bytes_peak"]},
                 {"width", width},
                 {"height", height}};
  out["views"] = measure_views(project, site, width, height);
  // Not built yet: edits in place, 3D selection.
  for (const char* field : {"hide_ms", "recolor_ms", "commit_1m_points_ms", "insert_scan_seconds"})
    out[field] = nullptr;
  out["selection"] = nlohmann::json::array();
  return out;
}

}  // namespace scanbench::bench

#include "bench/bench_lod.hpp"

#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/simulation/sites.hpp"
#include "acquisition/simulation/virtual_scanner.hpp"
#include "bench/campus_views.hpp"
#include "bench/child_process.hpp"
#include "bench/image_metrics.hpp"
#include "bench/scratch_folder.hpp"
#include "bench/simulated_site.hpp"
#include "modeling/color_commands.hpp"
#include "modeling/lod/build_lod.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/tree_commands.hpp"
#include "render/device.hpp"
#include "render/lod_renderer.hpp"

namespace scanbench::bench {
namespace {

// `scanbench lod` on `project` with `threads` (0: every core; --rebuild
// when `rebuild`), its JSON with the process's wall time and peak memory.
nlohmann::json timed_lod(const std::filesystem::path& project, int threads,
                         const std::filesystem::path& dir, bool rebuild, const std::string& stage) {
  std::vector<std::string> arguments = {"lod", project.string(), "--json", "--threads",
                                        std::to_string(threads)};
  if (rebuild) arguments.push_back("--rebuild");
  const ChildRun run = run_scanbench(stage, arguments, dir);
  if (run.exit_code != 0) {
    throw std::runtime_error("bench lod: scanbench lod exited with " +
                             std::to_string(run.exit_code) + ": " + run.err);
  }
  nlohmann::json built = nlohmann::json::parse(run.out);
  built["process_seconds"] = run.seconds;
  built["peak_rss_bytes"] = run.peak_rss_bytes;
  return built;
}

nlohmann::json timed_build(const std::filesystem::path& project, int threads,
                           const std::filesystem::path& dir) {
  return timed_lod(project, threads, dir, true, "lod_" + std::to_string(threads));
}

// `scanbench lod` updating the store in place after a command; refuses a
// rebuild (the bench measures updates).
nlohmann::json timed_update(const std::filesystem::path& project, const std::filesystem::path& dir,
                            const std::string& stage) {
  nlohmann::json update = timed_lod(project, 0, dir, false, stage);
  if (!update["updated"].get<bool>()) {
    throw std::runtime_error("bench lod: the store was built again after " + stage + ": " +
                             update["why_built"].get<std::string>());
  }
  return update;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The truth object of `site`'s first scan whose pixels there come nearest
// a million points over the whole campaign (a scan of 3600 × 900 holds
// 3.24 M pixels; the other scans carry about as many again): its id and
// its in-model pixels.
std::pair<std::uint32_t, std::vector<std::uint32_t>> object_of_a_million(
    const SimulatedSite& site) {
  const acquisition::Scan& scan = site.scans.front();
  const double target = 0.5e6 * static_cast<double>(scan.pixel_count()) / (3600.0 * 900.0);
  std::map<std::uint32_t, std::vector<std::uint32_t>> pixels;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    const std::uint32_t id = site.truth.front().object_id[i];
    if (id != 0 && acquisition::in_model(scan, site.geometry.front(), i))
      pixels[id].push_back(static_cast<std::uint32_t>(i));
  }
  auto best = pixels.begin();
  for (auto at = pixels.begin(); at != pixels.end(); ++at) {
    if (std::abs(static_cast<double>(at->second.size()) - target) <
        std::abs(static_cast<double>(best->second.size()) - target))
      best = at;
  }
  return *best;
}

// Edits as a user makes them, the store updated in place (`scanbench lod`
// in a process of its own after each command): a truth object committed
// from the first scan and carried into the others; its hide and recolour,
// each shown by the next frame of the street view without a node
// uploaded or the store rewritten; its delete; then the undo of that.
nlohmann::json measure_edits(const std::filesystem::path& file, const SimulatedSite& site,
                             const std::filesystem::path& dir, int width, int height) {
  store::Project project = store::Project::open(file);
  const std::int64_t scan_id = project.scans().front().id;
  nlohmann::json out;
  const auto [truth_id, selection] = object_of_a_million(site);
  auto start = std::chrono::steady_clock::now();
  modeling::CommitSettings commit;
  commit.scan_id = scan_id;
  commit.name = "bench object";
  const std::int64_t node = modeling::commit_selection(project, commit, selection).node_id;
  out["commit_command_ms"] = ms_since(start);
  const nlohmann::json committed = timed_update(file, dir, "lod_commit");
  out["commit_points"] = committed["points_relabelled"];
  out["commit_store_ms"] = 1000.0 * committed["seconds"].get<double>();
  out["commit_nodes_written"] = committed["nodes_written"];
  out["commit_truth_object"] = truth_id;

  const std::unique_ptr<render::RenderDevice> device = render::make_headless_device();
  render::LodRenderer renderer(lod::LodStore::path_for(file), {});
  render::RenderSettings settings;
  const NamedView street = campus_views(width, height).at(1);
  const render::RenderView camera =
      render::make_render_view(street.camera, renderer.header().origin);
  renderer.show_project_state(project);
  renderer.draw_complete(camera, settings);
  // A command, then the next frame: what it costs to see it.
  const auto next_frame = [&](const std::function<void()>& command, const char* name) {
    const auto begin = std::chrono::steady_clock::now();
    command();
    const double command_ms = ms_since(begin);
    renderer.show_project_state(project);
    const render::LodFrameResult frame = renderer.draw(camera, settings);
    out[std::string(name) + "_ms"] = ms_since(begin);
    out[name] = {{"command_ms", command_ms},
                 {"frame_ms", frame.frame_ms},
                 {"frames", 1},
                 {"uploaded_nodes", frame.uploaded_nodes},
                 {"store_current", lod::current_lod_store(project).has_value()}};
  };
  // Hides or shows the object.
  const auto show = [&](bool shown) {
    modeling::NodeEdit edit;
    edit.node = node;
    edit.hidden = !shown;
    modeling::edit_node(project, edit);
  };
  next_frame([&] { show(false); }, "hide");
  show(true);
  next_frame(
      [&] {
        modeling::RecolorSettings recolor;
        recolor.node = node;
        recolor.set.hue_deg = 120.0;
        recolor.set.saturation = 1.5;
        modeling::recolor_object(project, recolor);
      },
      "recolor");
  start = std::chrono::steady_clock::now();
  modeling::DeleteSettings removal;
  removal.node = node;
  removal.points = modeling::DeletedPoints::kDeleted;
  modeling::delete_node(project, removal);
  out["delete_command_ms"] = ms_since(start);
  const nlohmann::json deleted = timed_update(file, dir, "lod_delete");
  out["delete_store_ms"] = 1000.0 * deleted["seconds"].get<double>();
  out["delete_points"] = deleted["points_removed"];
  project.undo();
  const nlohmann::json undone = timed_update(file, dir, "lod_undo_delete");
  out["undo_delete_store_ms"] = 1000.0 * undone["seconds"].get<double>();
  out["undo_delete_points"] = undone["points_added"];
  return out;
}

namespace sim = acquisition::sim;

// Each view of the project of the site's first `stations` scans as the
// streaming renderer draws it once the camera stops,
// from cold caches (a renderer just opened): the frames until the picture
// is complete, and that picture against the truth and against the full
// picture (every point of the store drawn, no level of detail).
nlohmann::json measure_views(const std::filesystem::path& project, const SimulatedSite& site,
                             std::size_t stations, int width, int height) {
  const sim::Site scene_site = sim::make_site("campus", kSiteSeed, static_cast<int>(stations));
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
    const std::vector<std::uint8_t> mask = sampled_mask(truth, view.camera, site, stations);
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
  // One scan more than the project holds at first: the one inserted.
  const std::size_t stations = options.smoke ? 2 : 4;
  const SimulatedSite site =
      simulate_site("campus", scanner, static_cast<int>(stations) + 1, SiteLighting::kReference);
  const ScratchFolder scratch("lod");
  const std::filesystem::path project = scratch.path() / "campus.sbproj";
  store_site_project(site, project, stations);

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
  out["views"] = measure_views(project, site, stations, width, height);
  const nlohmann::json edits = measure_edits(project, site, scratch.path(), width, height);
  out["edits"] = edits;
  out["hide_ms"] = edits["hide_ms"];
  out["recolor_ms"] = edits["recolor_ms"];
  out["commit_1m_points_ms"] = edits["commit_store_ms"];
  // A new scan: imported, the campaign merged again, the store updated in
  // place; against building the store of the grown campaign anew.
  {
    store::Project grown = store::Project::open(project);
    add_site_scan(site, stations, grown);
  }
  const nlohmann::json inserted = timed_update(project, scratch.path(), "lod_insert");
  out["insert_scan_seconds"] = inserted["seconds"];
  const nlohmann::json rebuilt = timed_build(project, 0, scratch.path());
  out["full_rebuild_seconds"] = rebuilt["seconds"];
  out["full_rebuild"] = {{"points", rebuilt["points"]},
                         {"nodes", rebuilt["nodes"]},
                         {"peak_rss_bytes", rebuilt["peak_rss_bytes"]}};
  out["insert"] = {
      {"points_added", inserted["points_added"]},   {"points_removed", inserted["points_removed"]},
      {"nodes_written", inserted["nodes_written"]}, {"nodes", inserted["nodes"]},
      {"phase_seconds", inserted["phase_seconds"]}, {"peak_rss_bytes", inserted["peak_rss_bytes"]}};
  out["selection"] = nlohmann::json::array();  // 3D selection: still to come
  return out;
}

}  // namespace scanbench::bench

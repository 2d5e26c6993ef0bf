#include "bench/bench_lod.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "acquisition/formats/picture_file.hpp"
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
#include "render/lasso.hpp"
#include "render/lod_renderer.hpp"
#include "segmentation/pixel_set.hpp"

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

namespace sim = acquisition::sim;

// A store point by where it came from, and where it is (model frame).
struct StorePoint {
  std::int64_t scan_id = 0;
  std::uint32_t pixel = 0;
  Eigen::Vector3f position;
};

// The truth object each store point samples: its id in the site's truth
// (0: none), found through its scan and pixel.
class StoreTruth {
 public:
  StoreTruth(const lod::LodStore& store, const store::Project& project, const SimulatedSite& site) {
    const std::vector<store::StoredScanSummary> scans = project.scans();
    for (const lod::LodScan& scan : store.scans()) {
      for (std::size_t k = 0; k < scans.size(); ++k) {
        if (scans[k].id == scan.scan_id) site_scan_[scan.index] = k;
      }
      scan_ids_[scan.index] = scan.scan_id;
    }
    truth_ = &site.truth;
  }
  std::uint32_t truth_of(const lod::LodPoint& q) const {
    return (*truth_)[site_scan_.at(q.scan)].object_id[q.pixel];
  }
  std::int64_t scan_id(const lod::LodPoint& q) const { return scan_ids_.at(q.scan); }
  std::size_t site_scan(const lod::LodPoint& q) const { return site_scan_.at(q.scan); }
  std::size_t site_scan_of(std::int64_t scan_id) const {
    for (const auto& [index, id] : scan_ids_) {
      if (id == scan_id) return site_scan_.at(index);
    }
    throw std::logic_error("bench lod: a selection of a scan the store does not hold");
  }

 private:
  std::map<std::uint16_t, std::size_t> site_scan_;
  std::map<std::uint16_t, std::int64_t> scan_ids_;
  const std::vector<sim::ScanTruth>* truth_ = nullptr;
};

// Calls `use` with every point of the store, its position in the model frame.
void for_each_store_point(
    const lod::LodStore& store,
    const std::function<void(const lod::LodPoint&, const Eigen::Vector3f&)>& use) {
  for (const lod::LodNodeInfo& node : store.nodes()) {
    const Eigen::Vector3f corner = store.header().cube.node_box(node.key).min().cast<float>();
    for (const lod::LodPoint& q : store.read_points(node.key)) {
      use(q,
          corner + Eigen::Vector3f(static_cast<float>(q.offset[0]), static_cast<float>(q.offset[1]),
                                   static_cast<float>(q.offset[2])) *
                       static_cast<float>(lod::kQuantumM));
    }
  }
}

// The truth object seen by `site`'s first scan whose points in the store
// of `file` come nearest a million: its id, and its in-model pixels in
// that scan (the commit carries them into the other scans).
std::pair<std::uint32_t, std::vector<std::uint32_t>> object_of_a_million(
    const std::filesystem::path& file, const SimulatedSite& site) {
  const acquisition::Scan& scan = site.scans.front();
  std::map<std::uint32_t, std::vector<std::uint32_t>> pixels;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    const std::uint32_t id = site.truth.front().object_id[i];
    if (id != 0 && acquisition::in_model(scan, site.geometry.front(), i))
      pixels[id].push_back(static_cast<std::uint32_t>(i));
  }
  std::map<std::uint32_t, std::uint64_t> in_store;
  {
    const store::Project project = store::Project::open_read_only(file);
    const lod::LodStore store = lod::LodStore::open(lod::LodStore::path_for(file));
    const StoreTruth truth(store, project, site);
    for_each_store_point(store, [&](const lod::LodPoint& q, const Eigen::Vector3f&) {
      ++in_store[truth.truth_of(q)];
    });
  }
  const auto off_a_million = [&](std::uint32_t id) {
    return std::abs(static_cast<double>(in_store[id]) - 1e6);
  };
  auto best = pixels.begin();
  for (auto at = pixels.begin(); at != pixels.end(); ++at) {
    if (off_a_million(at->first) < off_a_million(best->first)) best = at;
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
  const auto [truth_id, selection] = object_of_a_million(file, site);
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

// Each view of the project of the site's first `stations` scans as the
// streaming renderer draws it once the camera stops,
// from cold caches (a renderer just opened): the frames until the picture
// is complete, and that picture against the truth and against the full
// picture (every point of the store drawn, no level of detail).
nlohmann::json measure_views(const std::filesystem::path& project, const SimulatedSite& site,
                             std::size_t stations, int width, int height,
                             std::size_t preview_budget) {
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
    // for the nodes being read, and draws a preview within the moving
    // frames' budget while some are still being read.
    render::RenderSettings refining = settings;
    refining.culling.preview_budget = preview_budget;
    std::size_t previews = 0;
    while (true) {
      const render::LodFrameResult frame =
          streaming.draw(camera, refining, std::chrono::milliseconds(250));
      previews += frame.preview ? 1 : 0;
      if (frame.complete()) break;
      ++frames;
    }
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
        {"converge_frames", frames},
        {"converge_previews", previews}};
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

// ---- 3D selection -----------------------------------------------------------

// The objects the bench selects: of each kind, the one with the most
// points in the store (counting its parts: a tree's crown and trunk, a
// wall's windows, doors and signs). Ids by kind, and each truth id's root
// among them.
struct SelectionTargets {
  std::vector<std::pair<std::string, sim::ObjectId>> objects;  // kind, id
  std::map<sim::ObjectId, sim::ObjectId> root_of;              // truth id → chosen object
};

SelectionTargets choose_targets(const lod::LodStore& store, const StoreTruth& truth,
                                const SimulatedSite& site) {
  static const std::vector<std::string> kKinds = {"wall", "tree", "car", "lamp_post", "low_wall"};
  // Each truth id's ancestor of one of the kinds (its own kind first).
  const auto info = [&site](sim::ObjectId id) -> const sim::ObjectInfo* {
    return id == 0 || id > site.objects.size() ? nullptr : &site.objects[id - 1];
  };
  const auto ancestor = [&](sim::ObjectId id) -> sim::ObjectId {
    for (const sim::ObjectInfo* o = info(id); o != nullptr; o = info(o->parent)) {
      if (std::find(kKinds.begin(), kKinds.end(), o->kind) != kKinds.end()) return o->id;
    }
    return 0;
  };
  std::map<sim::ObjectId, std::size_t> points;
  std::map<sim::ObjectId, sim::ObjectId> root_of;
  std::map<sim::ObjectId, Eigen::AlignedBox3f> boxes;  // of each truth id's points
  for_each_store_point(store, [&](const lod::LodPoint& q, const Eigen::Vector3f& position) {
    const sim::ObjectId id = truth.truth_of(q);
    boxes[id].extend(position);
    auto found = root_of.find(id);
    if (found == root_of.end()) found = root_of.emplace(id, ancestor(id)).first;
    if (found->second != 0) ++points[found->second];
  });
  SelectionTargets out;
  for (const std::string& kind : kKinds) {
    sim::ObjectId best = 0;
    for (const auto& [id, count] : points) {
      if (info(id)->kind == kind && (best == 0 || count > points[best])) best = id;
    }
    if (best != 0) out.objects.emplace_back(kind, best);
  }
  for (const auto& [id, root] : root_of) {
    for (const auto& [kind, chosen] : out.objects) {
      if (root == chosen) out.root_of[id] = chosen;
    }
  }
  // A wall is selected as its façade: with the windows, doors and signs
  // of its building set in it (siblings in the truth, within 0.3 m of its box).
  for (const auto& [kind, chosen] : out.objects) {
    if (kind != "wall") continue;
    const Eigen::AlignedBox3f& wall = boxes.at(chosen);
    const Eigen::AlignedBox3f near(wall.min().array() - 0.3f, wall.max().array() + 0.3f);
    for (const auto& [id, box] : boxes) {
      const sim::ObjectInfo* o = info(id);
      if (o != nullptr && id != chosen && o->parent == info(chosen)->parent &&
          (o->kind == "window" || o->kind == "door" || o->kind == "sign") && near.contains(box))
        out.root_of[id] = chosen;
    }
  }
  return out;
}

// The lassos a careful user draws around `points` (model frame) on
// `view`'s picture: the outlines of what they cover, widened by a few
// pixels (a hand does not trace pixel for pixel), one per separate part.
std::vector<render::Lasso> outline_lassos(const render::RenderView& view,
                                          const std::vector<Eigen::Vector3f>& points) {
  cv::Mat mask = cv::Mat::zeros(view.height, view.width, CV_8U);
  for (const Eigen::Vector3f& p : points) {
    const std::optional<Eigen::Vector2f> at = render::project_to_picture(view, p);
    if (!at) continue;
    const int x = static_cast<int>(at->x()), y = static_cast<int>(at->y());
    if (x >= 0 && y >= 0 && x < view.width && y < view.height) mask.at<std::uint8_t>(y, x) = 255;
  }
  // Closed over the gaps between samples, then 3 pixels wider.
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
  cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  std::vector<render::Lasso> lassos;
  for (const std::vector<cv::Point>& contour : contours) {
    if (cv::contourArea(contour) < 16.0) continue;  // a stray sample, not a part
    std::vector<cv::Point> polygon;
    cv::approxPolyDP(contour, polygon, 1.5, true);
    std::vector<Eigen::Vector2f> vertices;
    for (const cv::Point& v : polygon)
      vertices.emplace_back(static_cast<float>(v.x) + 0.5f, static_cast<float>(v.y) + 0.5f);
    lassos.emplace_back(std::move(vertices));
  }
  return lassos;
}

// Pixels by scan id, each scan's ascending.
using PixelsByScan = std::map<std::int64_t, std::vector<std::uint32_t>>;

PixelsByScan unite(const PixelsByScan& a, const PixelsByScan& b) {
  PixelsByScan out = a;
  for (const auto& [scan, pixels] : b) out[scan] = segmentation::unite(out[scan], pixels);
  return out;
}

std::size_t count(const PixelsByScan& a) {
  std::size_t n = 0;
  for (const auto& [scan, pixels] : a) n += pixels.size();
  return n;
}

// How many pixels `a` and `b` share.
std::size_t common(const PixelsByScan& a, const PixelsByScan& b) {
  std::size_t n = 0;
  for (const auto& [scan, pixels] : a) {
    const auto other = b.find(scan);
    if (other == b.end()) continue;
    n += pixels.size() - segmentation::subtract(pixels, other->second).size();
  }
  return n;
}

// A camera at `eye` (model frame) that frames `points`, `width` × `height`.
render::RenderView framing(const Eigen::Vector3f& eye, const std::vector<Eigen::Vector3f>& points,
                           const Eigen::Vector3d& origin, int width, int height) {
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& p : points) centre += p;
  centre /= static_cast<float>(points.size());
  const Eigen::Vector3f ahead = (centre - eye).normalized();
  float widest = 0.0f;  // [rad] from the line of sight
  for (const Eigen::Vector3f& p : points)
    widest =
        std::max(widest, std::acos(std::clamp(ahead.dot((p - eye).normalized()), -1.0f, 1.0f)));
  acquisition::CameraView camera;
  camera.width = width;
  camera.height = height;
  camera.vertical_fov_deg = std::clamp(2.3 * widest * 180.0 / std::numbers::pi, 10.0, 100.0);
  camera.T_world_camera =
      acquisition::look_at(origin + eye.cast<double>(), origin + centre.cast<double>());
  return render::make_render_view(camera, origin);
}

// Five objects selected as a user does in the 3D view: a lasso traced
// around each one's outline (outline_lassos), taking the points in front
// (a tree's down to half its width behind the nearest leaves),
// from the view that shows it best, then from the other side where that
// adds what the first could not see. The views are chosen as a user turns
// the view until the object is in the clear, by what the lasso would take
// (the truth counting what is the object's): of 24 views around it (12
// directions, at eye level and 5 m above, framing all of it), the one
// whose lassos take the most of it less the most of anything else; then,
// from at least 120° around, the one adding most, if more than 2 % of it.
// The selection's points against the truth's in the store (its parts
// too): intersection over union.
nlohmann::json measure_selection(const std::filesystem::path& file, const SimulatedSite& site,
                                 int width, int height, const std::filesystem::path& pictures) {
  const store::Project project = store::Project::open(file);
  const std::filesystem::path store_file = lod::LodStore::path_for(file);
  const lod::LodStore store = lod::LodStore::open(store_file);
  const StoreTruth truth(store, project, site);
  const SelectionTargets targets = choose_targets(store, truth, site);
  // The chosen objects' points, and how many each scan gave.
  std::map<sim::ObjectId, std::vector<StorePoint>> members;
  std::map<sim::ObjectId, std::map<std::size_t, std::size_t>> by_scan;
  for_each_store_point(store, [&](const lod::LodPoint& q, const Eigen::Vector3f& position) {
    const auto root = targets.root_of.find(truth.truth_of(q));
    if (root == targets.root_of.end()) return;
    members[root->second].push_back({truth.scan_id(q), q.pixel, position});
    ++by_scan[root->second][truth.site_scan(q)];
  });
  const std::unique_ptr<render::RenderDevice> device = render::make_headless_device();
  render::LodRenderer renderer(store_file, {});
  renderer.show_project_state(project);
  const Eigen::Vector3d origin = renderer.header().origin;
  const render::RenderSettings settings;
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [kind, id] : targets.objects) {
    const std::vector<StorePoint>& object = members[id];
    std::vector<Eigen::Vector3f> positions;
    for (const StorePoint& p : object) positions.push_back(p.position);
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& p : positions) centre += p;
    centre /= static_cast<float>(positions.size());
    float radius = 0.0f;
    for (const Eigen::Vector3f& p : positions) radius = std::max(radius, (p - centre).norm());
    PixelsByScan truth_pixels;
    for (const StorePoint& p : object) truth_pixels[p.scan_id].push_back(p.pixel);
    for (auto& [scan, pixels] : truth_pixels) std::sort(pixels.begin(), pixels.end());
    // A crown is a volume seen through its leaves: its lassos reach half
    // its width behind the nearest leaves (the rest from the other side).
    // Other objects are surfaces: what is in front.
    Eigen::AlignedBox3f bounds;
    for (const Eigen::Vector3f& p : positions) bounds.extend(p);
    const float depth_m = kind == "tree" ? 0.5f * bounds.sizes().head<2>().maxCoeff() : 0.0f;
    // The lassos around the object's outline from `eye`, what they take.
    const auto lasso_from = [&](const Eigen::Vector3f& eye, std::size_t* lassos) {
      const render::RenderView view = framing(eye, positions, origin, width, height);
      PixelsByScan taken;
      for (const render::Lasso& lasso : outline_lassos(view, positions)) {
        if (lassos != nullptr) ++*lassos;
        taken = unite(taken, renderer.select(view, lasso, settings, {.depth_m = depth_m}).pixels);
      }
      return taken;
    };
    // The net of a selection: the object's points it holds less the others.
    const auto net = [&](const PixelsByScan& taken) {
      const std::size_t hits = common(taken, truth_pixels);
      return static_cast<double>(hits) - static_cast<double>(count(taken) - hits);
    };
    // The views a user turns to: 12 around the object, at eye level (the
    // height of the station that gave it most points) and 5 m above, each
    // far enough back to frame all of it (it spans at most 50°).
    std::size_t best_station = 0, most = 0;
    for (const auto& [k, count] : by_scan[id]) {
      if (count > most) std::tie(best_station, most) = std::pair{k, count};
    }
    const float eye_z =
        static_cast<float>(site.scans[best_station].T_world_scan.translation().z() - origin.z());
    const float away = radius / std::sin(static_cast<float>(std::numbers::pi) / 7.2f);
    struct Candidate {
      float azimuth = 0.0f;
      Eigen::Vector3f eye;
      PixelsByScan taken;
    };
    std::vector<Candidate> candidates;
    for (int a = 0; a < 12; ++a) {
      const float azimuth = static_cast<float>(a) * static_cast<float>(std::numbers::pi) / 6.0f;
      for (const float above : {0.0f, 5.0f}) {
        const Eigen::Vector3f eye(centre.x() + away * std::cos(azimuth),
                                  centre.y() + away * std::sin(azimuth), eye_z + above);
        candidates.push_back({azimuth, eye, lasso_from(eye, nullptr)});
      }
    }
    // The view that shows it best, then, from at least 120° around it, the
    // one that adds most of what the first could not see, if that is more
    // than 2 % of it.
    const auto first = std::max_element(
        candidates.begin(), candidates.end(),
        [&](const Candidate& a, const Candidate& b) { return net(a.taken) < net(b.taken); });
    std::vector<Eigen::Vector3f> eyes = {first->eye};
    const double alone = net(first->taken);
    double gain = 0.02 * static_cast<double>(object.size());
    const Candidate* second = nullptr;
    for (const Candidate& c : candidates) {
      const float apart = std::abs(
          std::remainder(c.azimuth - first->azimuth, 2.0f * static_cast<float>(std::numbers::pi)));
      if (apart < 2.0f * static_cast<float>(std::numbers::pi) / 3.0f) continue;
      const double more = net(unite(first->taken, c.taken)) - alone;
      if (more > gain) std::tie(second, gain) = std::pair{&c, more};
    }
    if (second != nullptr) eyes.push_back(second->eye);
    // The chosen views' lassos again, timed: what the user's selection costs.
    const auto start = std::chrono::steady_clock::now();
    PixelsByScan selected;
    std::size_t lassos = 0;
    for (const Eigen::Vector3f& eye : eyes) selected = unite(selected, lasso_from(eye, &lassos));
    const double select_ms = ms_since(start);
    if (!pictures.empty()) {
      // Each view as drawn, the object's points the lassos took in yellow,
      // those they missed in red.
      std::filesystem::create_directories(pictures);
      std::string stem = site.objects[id - 1].name;
      std::replace(stem.begin(), stem.end(), '/', '_');
      for (std::size_t v = 0; v < eyes.size(); ++v) {
        const render::RenderView view = framing(eyes[v], positions, origin, width, height);
        renderer.draw_complete(view, settings);
        std::vector<std::uint8_t> rgb = renderer.read_image().rgb();
        for (const StorePoint& p : object) {
          const auto at = render::project_to_picture(view, p.position);
          if (!at || at->x() < 0 || at->y() < 0 || at->x() >= width || at->y() >= height) continue;
          const auto in = selected.find(p.scan_id);
          const bool taken = in != selected.end() &&
                             std::binary_search(in->second.begin(), in->second.end(), p.pixel);
          const std::size_t i =
              3 * (static_cast<std::size_t>(at->y()) * width + static_cast<std::size_t>(at->x()));
          rgb[i] = 255;
          rgb[i + 1] = taken ? 220 : 0;
          rgb[i + 2] = 0;
        }
        acquisition::write_rgb_picture(
            pictures / ("selection_" + stem + "_" + std::to_string(v) + ".png"), width, height,
            rgb);
      }
    }
    std::size_t chosen = 0, both = 0;
    for (const auto& [scan, pixels] : selected) chosen += pixels.size();
    // The object's points the lassos missed, by the kind of its part.
    std::map<std::string, std::size_t> missed;
    for (const StorePoint& p : object) {
      const auto in = selected.find(p.scan_id);
      const bool taken =
          in != selected.end() && std::binary_search(in->second.begin(), in->second.end(), p.pixel);
      both += taken;
      if (!taken) {
        const sim::ObjectId part = site.truth[truth.site_scan_of(p.scan_id)].object_id[p.pixel];
        ++missed[site.objects[part - 1].kind];
      }
    }
    const std::size_t either = chosen + object.size() - both;
    // What else the lassos took, by the kind of object it samples.
    std::map<std::string, std::size_t> others;
    for (const auto& [scan, pixels] : selected) {
      const std::vector<sim::ObjectId>& ids = site.truth[truth.site_scan_of(scan)].object_id;
      for (const std::uint32_t pixel : pixels) {
        const auto root = targets.root_of.find(ids[pixel]);
        if (root != targets.root_of.end() && root->second == id) continue;
        ++others[ids[pixel] == 0 ? std::string("nothing") : site.objects[ids[pixel] - 1].kind];
      }
    }
    out.push_back({{"name", site.objects[id - 1].name + (kind == "wall" ? " (façade)" : "")},
                   {"kind", kind},
                   {"selection_iou",
                    either == 0 ? 0.0 : static_cast<double>(both) / static_cast<double>(either)},
                   {"truth_points", object.size()},
                   {"selected_points", chosen},
                   {"other_points", others},
                   {"missed_points", missed},
                   {"views", eyes.size()},
                   {"depth_m", depth_m},
                   {"lassos", lassos},
                   {"select_ms", select_ms}});
  }
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
  // Previews within the budget the fly-through's moving frames settled at,
  // as the workbench's are after the camera moved.
  out["views"] = measure_views(project, site, stations, width, height,
                               path["points_per_frame_p50"].get<std::size_t>());
  out["selection"] = measure_selection(project, site, width, height, options.pictures);
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
  return out;
}

}  // namespace scanbench::bench

// The streaming splat renderer (docs/lod.md; seed 000 §4): draws a
// level-of-detail store through the splat passes (splat_passes.hpp). Each
// frame plans the nodes the view wants (lod_frame_plan.hpp); a loader
// thread reads the missing ones from disk into an LRU cache in main memory
// (lod_node_cache.hpp), and the renderer uploads them, as stored, into an
// LRU cache on the device, each with a byte limit. A node not on the device
// yet is stood in for by its ancestors, whose splats grow to cover it.
//
// Visibility and colour edits are tables on the device (per object: shown,
// its resolved edit; per scan: its colour correction), so hiding or
// recolouring an object changes the next frame and rewrites no node.
//
// Needs the device's context current for its whole life.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "modeling/store/color_edit.hpp"
#include "modeling/store/project.hpp"
#include "render/lasso.hpp"
#include "render/lod_frame_plan.hpp"
#include "render/splat_passes.hpp"

namespace scanbench::render {

struct LodRendererLimits {
  std::uint64_t memory_bytes = std::uint64_t{512} << 20;  // points in main memory
  std::uint64_t device_bytes = std::uint64_t{1} << 30;    // points on the device
  // Uploaded in one frame at most, so a frame stays short while the camera
  // moves (draw_complete() has no limit); 0: no limit.
  std::uint64_t upload_bytes_per_frame = std::uint64_t{64} << 20;
};

struct LodFrameResult {
  LodFramePlan plan;
  double frame_ms = 0.0;   // CPU wall time of the frame, finished on the device
  double gpu_ms = -1.0;    // the device's own time; negative where it cannot say
  double plan_ms = 0.0;    // of frame_ms: planning (the walk of the tree)
  double upload_ms = 0.0;  // of frame_ms: uploading nodes to the device
  std::size_t uploaded_nodes = 0;
  std::uint64_t uploaded_bytes = 0;
  // The frame drew a preview within CullSettings::preview_budget, nodes
  // it wants being still read.
  bool preview = false;
  // Every node the view wants is drawn (plan.wanted is empty): the
  // picture will not refine further.
  bool complete() const { return plan.wanted.empty(); }
};

// A point of the store under a ray, as a complete picture draws it.
struct LodPick {
  lod::LodPoint point;       // as stored: its scan, pixel and object
  std::int64_t object = 0;   // its object as the view shows it (0: none, or one not in the tree)
  Eigen::Vector3f position;  // model frame (metres from the store's origin)
  float distance_m = 0.0f;   // along the ray
};

// How a selection in the 3D view takes points.
struct LodSelectOptions {
  // How far behind the nearest surface the view draws at its pixel a
  // point the lasso encloses may lie and still be taken [m], beyond a
  // tolerance of 2 drawn splat radii and 0.5 % of the distance. 0: only
  // what a person sees in front (a lasso over a wall does not take what
  // lies behind it); a crown's depth: the leaves inside it too;
  // kEveryDepth: every point inside the lasso. Back faces the view culls
  // hide nothing, and are taken only with a depth beyond 0.
  float depth_m = 0.0f;
  // Only points still to be segmented (in no object): those a selection
  // may hold. Points of objects still hide what lies behind them.
  bool open_only = true;
  // At most this many of the selected points' positions, spread evenly
  // over them, for the view to mark the selection with.
  std::size_t sample = 0;
};
inline constexpr float kEveryDepth = std::numeric_limits<float>::infinity();

struct LodSelection {
  // By scan id, each scan's pixels ascending: the per-scan pixel
  // selections the segmentation's commands take.
  std::map<std::int64_t, std::vector<std::uint32_t>> pixels;
  std::size_t points = 0;
  std::vector<Eigen::Vector3f> sample;  // model frame
};

// A point of a sample of the whole model.
struct LodSample {
  Eigen::Vector3f position;  // model frame
  Eigen::Vector3f normal;    // zero: unknown
  std::int64_t object = 0;   // as stored
};

class LodRenderer {
 public:
  // Opens the store at `store_file` (throws core::InputError naming it when
  // it is missing or damaged) and starts its loader.
  LodRenderer(const std::filesystem::path& store_file, const LodRendererLimits& limits);
  ~LodRenderer();
  LodRenderer(const LodRenderer&) = delete;
  LodRenderer& operator=(const LodRenderer&) = delete;

  const lod::LodHeader& header() const { return hierarchy_.header; }
  const LodHierarchy& hierarchy() const { return hierarchy_; }

  // What the next frame shows of the objects: each node's visibility (a
  // node below a hidden group is hidden) and resolved colour edit
  // (modeling/color_pipeline.hpp). Points of objects not in `tree` show as
  // no object's.
  void set_objects(const std::vector<store::ObjectNode>& tree);
  // Each scan's colour correction, by scan id; scans not in the map show
  // their recorded colours.
  void set_scan_corrections(const std::map<std::int64_t, store::ScanColorCorrection>& corrections);
  // Both, as `project` has them now.
  void show_project_state(const store::Project& project);

  // Draws a frame through `view` (in the store's frame: metres from
  // header().origin) with what is on the device, uploading at most the
  // per-frame limit of what the loader has read and asking it for the
  // rest; for up to `wait_for_nodes` it waits for the loader and takes in
  // what it reads (a still camera refining: fewer frames, each drawing
  // more). Leaves the context's GL state as it found it. Throws
  // core::InputError naming the store and the node when a node the view
  // wants could not be read.
  LodFrameResult draw(const RenderView& view, const RenderSettings& settings,
                      std::chrono::milliseconds wait_for_nodes = std::chrono::milliseconds(0));
  // Loads everything the view wants first: the converged picture. Throws
  // as draw().
  LodFrameResult draw_complete(const RenderView& view, const RenderSettings& settings);

  // Whether a frame through the last frame's view would draw more: nodes it
  // wanted have been read since.
  bool has_more_to_draw();

  // The point whose splat the ray from `origin` along unit `direction`
  // (model frame) meets first among every point of the store, drawn as
  // `settings` draws them (its clipping, splat scale and orientation):
  // the points a full picture shows, whatever level of detail the last
  // frame drew. Hidden objects' points and points facing away are not hit.
  // Walks the nodes whose bounds the ray crosses; reads those the memory
  // cache does not hold from the store.
  std::optional<LodPick> pick(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                              const RenderSettings& settings);

  // The store was updated in place (modeling/lod/update_lod.hpp): reads its
  // hierarchy again, and drops what the caches hold of the nodes
  // `rewritten` (by code: rewritten, new or removed), keeping every other
  // node in memory and on the device, so the next frame redraws the
  // picture but the changed nodes from what it holds.
  void follow_update(std::span<const std::uint64_t> rewritten);

  // The points whose centres `lasso` (picture pixels of `view`) encloses,
  // among those the view would draw (shown objects, within the clipping box
  // and slice), taken as `options` says. Every point of the store counts,
  // whatever level of detail the last frame drew. Walks the nodes whose
  // bounds may project into the lasso (and, seeing which points are in
  // front, those whose splats may cover it); reads those the memory cache
  // does not hold from the store.
  LodSelection select(const RenderView& view, const Lasso& lasso, const RenderSettings& settings,
                      const LodSelectOptions& options = {});
  // The volumetric brush (seed 002): the points within `radius_m` of
  // `centre` (model frame) among those the view would draw, taken as
  // `options` says (depth_m does not apply). Walks the nodes whose
  // bounds meet the sphere.
  LodSelection select_sphere(const Eigen::Vector3f& centre, float radius_m,
                             const RenderSettings& settings, const LodSelectOptions& options = {});

  // A sample spread over the whole model: the points of its shallowest
  // nodes (each an even subsample of its region), at least `count` where
  // the store holds as many. Read from the store.
  std::vector<LodSample> sample(std::size_t count);

  // The last frame, without its guard band; asserts that one was drawn.
  RenderedImage read_image() const;
  PictureTexture picture_texture() const;

  std::uint64_t device_bytes() const;
  std::uint64_t device_peak_bytes() const;
  std::uint64_t memory_peak_bytes() const;

 private:
  struct Gpu;
  // Reads the store's hierarchy and what follows from it (the nodes'
  // subtree radii, the scans), with an empty memory cache for it.
  void read_hierarchy();
  LodFramePlan plan(const RenderView& banded_view, const RenderSettings& settings) const;
  // A frame: plans, uploads (at most `upload_limit` bytes; 0: no limit)
  // and waits for the loader until `until` (none: until the view has
  // every node it wants), then draws.
  LodFrameResult frame(const RenderView& picture_view, const RenderSettings& settings,
                       std::optional<std::chrono::steady_clock::time_point> until,
                       std::uint64_t upload_limit);
  // Uploads the wanted nodes the memory cache holds, within `byte_limit`
  // (0: none); returns how many.
  std::size_t upload(const std::vector<std::size_t>& wanted, std::uint64_t byte_limit,
                     LodFrameResult& result);
  // Node `k`'s corner, model frame [m].
  Eigen::Vector3f node_corner_m(std::size_t k) const;
  // The octants of a drawn node whose points are not all drawn (bit k:
  // octant k): its splats there grow to cover them.
  std::uint32_t missing_octants(const LodNodeDraw& draw) const;
  // Node `k`'s points, from the memory cache or read from the store.
  void with_node_points(std::size_t k,
                        const std::function<void(std::span<const lod::LodPoint>)>& use);
  // Node `k`'s points the view would draw (of shown objects, kept by
  // `clipping`): use(point, its object as the view shows it, its position).
  void for_each_shown_point(
      std::size_t k, const Clipping& clipping,
      const std::function<void(const lod::LodPoint&, std::int64_t, const Eigen::Vector3f&)>& use);
  // Throws when a node of `wanted` could not be read.
  void refuse_failed(const std::vector<std::size_t>& wanted) const;
  double issue(const RenderView& banded_view, const RenderSettings& settings,
               const LodFramePlan& plan);

  LodHierarchy hierarchy_;
  LodFramePlan last_plan_;
  std::vector<float> subtree_radius_;    // each node's largest splat radius, its descendants' too
  std::optional<lod::LodStore> reader_;  // for pick() and sample(), opened when first needed
  // Per object id (as the tables on the device): shown, and in the tree.
  std::vector<std::uint8_t> object_shown_, object_known_;
  std::filesystem::path store_file_;
  std::map<std::int64_t, std::uint16_t> scan_of_id_;  // project scan id → store index
  std::vector<std::int64_t> scan_ids_;                // store index → project scan id
  LodRendererLimits limits_;
  Eigen::Vector2f height_range_{0.0f, 1.0f};
  std::unique_ptr<Gpu> gpu_;
};

}  // namespace scanbench::render

#include "render/lod_renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <queue>
#include <unordered_map>
#include <unordered_set>

#include "core/errors.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/shown_nodes.hpp"
#include "render/gl_objects.hpp"
#include "render/lod_node_cache.hpp"
#include "render/pick.hpp"
#include "render/splat_shaders.hpp"

namespace scanbench::render {

namespace {

constexpr std::size_t kPointBytes = sizeof(lod::LodPoint);

// The vertex formats of a stored point (lod_point.hpp), read by the LOD
// vertex stage (splat_shaders.cpp) from one interleaved buffer.
void describe_stored_points(GLuint vao) {
  struct Attribute {
    GLint size;
    GLenum type;
    bool integer;
    GLboolean normalized;
    std::size_t offset;
  };
  const std::array<Attribute, 9> attributes = {{
      {3, GL_UNSIGNED_INT, true, GL_FALSE, offsetof(lod::LodPoint, offset)},
      {1, GL_UNSIGNED_INT, true, GL_FALSE, offsetof(lod::LodPoint, object)},
      {1, GL_UNSIGNED_SHORT, true, GL_FALSE, offsetof(lod::LodPoint, scan)},
      {1, GL_UNSIGNED_BYTE, true, GL_FALSE, offsetof(lod::LodPoint, flags)},
      {1, GL_UNSIGNED_BYTE, false, GL_TRUE, offsetof(lod::LodPoint, intensity)},
      {2, GL_SHORT, true, GL_FALSE, offsetof(lod::LodPoint, normal)},
      {2, GL_SHORT, true, GL_FALSE, offsetof(lod::LodPoint, major_axis)},
      {2, GL_HALF_FLOAT, false, GL_FALSE, offsetof(lod::LodPoint, radii)},
      {4, GL_UNSIGNED_BYTE, false, GL_TRUE, offsetof(lod::LodPoint, rgb)},
  }};
  for (GLuint k = 0; k < attributes.size(); ++k) {
    const Attribute& a = attributes[k];
    const auto offset = static_cast<GLuint>(a.offset);
    if (a.integer) {
      glVertexArrayAttribIFormat(vao, k, a.size, a.type, offset);
    } else {
      glVertexArrayAttribFormat(vao, k, a.size, a.type, a.normalized, offset);
    }
    glVertexArrayAttribBinding(vao, k, 0);
    glEnableVertexArrayAttrib(vao, k);
  }
}

// A shader storage buffer holding `values` (at least one vec4: GL refuses
// empty storage).
GlBuffer storage_buffer(std::vector<float> values) {
  if (values.empty()) values.assign(4, 0.0f);
  GlBuffer buffer = make_buffer();
  glNamedBufferStorage(buffer.get(), static_cast<GLsizeiptr>(values.size() * sizeof(float)),
                       values.data(), 0);
  return buffer;
}

}  // namespace

struct LodRenderer::Gpu {
  struct DeviceNode {
    GlBuffer buffer;
    std::uint64_t bytes = 0;
    std::uint64_t last_frame = 0;
  };

  SplatPasses passes{shaders::splat_vertex()};
  GlVertexArray points;
  GlBuffer objects;  // ObjectStates (splat_shaders.cpp)
  GlBuffer scans;    // ScanCorrections
  std::unique_ptr<LodNodeCache> memory;
  std::unordered_map<std::size_t, DeviceNode> device;
  std::uint64_t device_bytes = 0, device_peak = 0;
  std::uint64_t frame = 0;
  std::vector<std::size_t> pending;  // wanted and in memory, not yet uploaded

  // Lets the least recently drawn nodes go until the device holds at most
  // `limit` bytes, never one this frame drew.
  void evict(std::uint64_t limit) {
    if (device_bytes <= limit) return;
    std::vector<std::pair<std::uint64_t, std::size_t>> by_age;
    for (const auto& [node, held] : device) {
      if (held.last_frame < frame) by_age.emplace_back(held.last_frame, node);
    }
    std::sort(by_age.begin(), by_age.end());
    for (const auto& [age, node] : by_age) {
      if (device_bytes <= limit) break;
      device_bytes -= device.at(node).bytes;
      device.erase(node);
    }
  }
};

LodRenderer::LodRenderer(const std::filesystem::path& store_file, const LodRendererLimits& limits)
    : store_file_(store_file), limits_(limits), gpu_(std::make_unique<Gpu>()) {
  read_hierarchy();
  gpu_->points = make_vertex_array();
  describe_stored_points(gpu_->points.get());
  set_objects({});
  set_scan_corrections({});
}

void LodRenderer::read_hierarchy() {
  const lod::LodStore store = lod::LodStore::open(store_file_);
  hierarchy_ = LodHierarchy::of(store);
  scan_of_id_.clear();
  scan_ids_.clear();
  for (const lod::LodScan& scan : store.scans()) {
    scan_of_id_[scan.scan_id] = scan.index;
    scan_ids_.push_back(scan.scan_id);
  }
  // Children after parents: backwards, each subtree's radius is whole
  // before its parent takes it in.
  subtree_radius_.assign(hierarchy_.nodes.size(), 0.0f);
  for (std::size_t k = hierarchy_.nodes.size(); k-- > 0;) {
    subtree_radius_[k] = std::max(subtree_radius_[k], hierarchy_.nodes[k].max_radius_m);
    for (const std::int32_t child : hierarchy_.children[k]) {
      if (child >= 0)
        subtree_radius_[k] =
            std::max(subtree_radius_[k], subtree_radius_[static_cast<std::size_t>(child)]);
    }
  }
  if (!hierarchy_.reach.empty() && !hierarchy_.reach.front().isEmpty())
    height_range_ = {hierarchy_.reach.front().min().z(), hierarchy_.reach.front().max().z()};
  std::vector<lod::NodeKey> keys;
  keys.reserve(hierarchy_.nodes.size());
  for (const lod::LodNodeInfo& node : hierarchy_.nodes) keys.push_back(node.key);
  gpu_->memory.reset();  // its loader stops first
  gpu_->memory = std::make_unique<LodNodeCache>(store_file_, std::move(keys), limits_.memory_bytes);
  last_plan_ = {};
  gpu_->pending.clear();
  reader_.reset();
}

void LodRenderer::follow_update(std::span<const std::uint64_t> rewritten) {
  const std::unordered_set<std::uint64_t> changed(rewritten.begin(), rewritten.end());
  std::vector<std::uint64_t> old_codes;
  old_codes.reserve(hierarchy_.nodes.size());
  for (const lod::LodNodeInfo& node : hierarchy_.nodes) old_codes.push_back(node.key.code());
  std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> in_memory =
      gpu_->memory->release();
  read_hierarchy();
  std::unordered_map<std::uint64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < hierarchy_.nodes.size(); ++k)
    index_of.emplace(hierarchy_.nodes[k].key.code(), k);
  // A node the update left alone, at its new index.
  const auto kept = [&](std::size_t old) -> std::optional<std::size_t> {
    if (changed.count(old_codes[old]) != 0) return std::nullopt;
    const auto found = index_of.find(old_codes[old]);
    if (found == index_of.end()) return std::nullopt;
    return found->second;
  };
  for (auto& [old, points] : in_memory) {
    if (const auto k = kept(old)) gpu_->memory->adopt(*k, std::move(points));
  }
  std::unordered_map<std::size_t, Gpu::DeviceNode> device;
  for (auto& [old, node] : gpu_->device) {
    if (const auto k = kept(old)) {
      device.emplace(*k, std::move(node));
    } else {
      gpu_->device_bytes -= node.bytes;
    }
  }
  gpu_->device = std::move(device);
}

LodRenderer::~LodRenderer() = default;

void LodRenderer::set_objects(const std::vector<store::ObjectNode>& tree) {
  std::int64_t largest = 0;
  for (const store::ObjectNode& node : tree) largest = std::max(largest, node.id);
  // Id 0 (no object) and every id up to the largest: shown, no edit.
  std::vector<float> table(16 * static_cast<std::size_t>(largest + 1), 0.0f);
  const auto neutral = [&](std::size_t id, bool shown, bool known) {
    float* s = &table[16 * id];
    s[0] = shown ? 1.0f : 0.0f;
    s[2] = known ? 1.0f : 0.0f;
    s[4] = s[5] = s[6] = 1.0f;  // transfer scale
    s[7] = 1.0f;                // contrast
    s[11] = 1.0f;               // gamma
    s[12] = 1.0f;               // cos hue
    s[14] = 1.0f;               // saturation
  };
  for (std::size_t id = 0; id <= static_cast<std::size_t>(largest); ++id)
    neutral(id, true, id == 0);
  object_shown_.assign(static_cast<std::size_t>(largest) + 1, 1);
  object_known_.assign(static_cast<std::size_t>(largest) + 1, 0);
  object_known_[0] = 1;
  const std::map<std::int64_t, bool> shown = modeling::shown_nodes(tree);
  for (const auto& [id, edit] : modeling::resolve_color_edits(tree)) {
    const auto at = static_cast<std::size_t>(id);
    neutral(at, shown.at(id), true);
    object_shown_[at] = shown.at(id) ? 1 : 0;
    object_known_[at] = 1;
    if (edit.identity()) continue;
    float* s = &table[16 * at];
    s[1] = 1.0f;
    s[3] = static_cast<float>(edit.brightness);
    for (int c = 0; c < 3; ++c) {
      s[4 + c] = static_cast<float>(edit.transfer.scale[c]);
      s[8 + c] = static_cast<float>(edit.transfer.offset[c]);
    }
    s[7] = static_cast<float>(edit.contrast);
    s[11] = static_cast<float>(edit.gamma);
    const double angle = edit.hue_deg * 3.14159265358979323846 / 180.0;
    s[12] = static_cast<float>(std::cos(angle));
    s[13] = static_cast<float>(std::sin(angle));
    s[14] = static_cast<float>(edit.saturation);
  }
  gpu_->objects = storage_buffer(std::move(table));
}

void LodRenderer::set_scan_corrections(
    const std::map<std::int64_t, store::ScanColorCorrection>& corrections) {
  std::size_t scans = 0;
  for (const auto& [id, index] : scan_of_id_) scans = std::max<std::size_t>(scans, index + 1u);
  std::vector<float> table(16 * scans, 0.0f);
  for (const auto& [id, correction] : corrections) {
    const auto found = scan_of_id_.find(id);
    if (found == scan_of_id_.end() || correction.identity()) continue;
    float* s = &table[16 * static_cast<std::size_t>(found->second)];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) s[4 * r + c] = static_cast<float>(correction.matrix(r, c));
      s[4 * r + 3] = static_cast<float>(correction.offset[r]);
    }
    s[12] = 1.0f;
  }
  gpu_->scans = storage_buffer(std::move(table));
}

void LodRenderer::show_project_state(const store::Project& project) {
  set_objects(project.object_nodes());
  set_scan_corrections(project.scan_color_corrections());
}

LodFramePlan LodRenderer::plan(const RenderView& banded_view,
                               const RenderSettings& settings) const {
  const CullSettings& cull = settings.culling;
  LodPlanSettings plan_settings;
  plan_settings.clipping = cull.clipping;
  plan_settings.frustum = cull.frustum;
  plan_settings.lod_pixels = cull.level_of_detail ? cull.lod_pixels : 0.0f;
  plan_settings.budget = cull.budget;
  // A still picture refines to the finer cells where the whole of it at
  // that fineness (every node in memory or not) stays within fine_points.
  if (cull.level_of_detail && cull.budget == 0 && cull.fine_lod_pixels > 0.0f &&
      cull.fine_lod_pixels < cull.lod_pixels) {
    LodPlanSettings fine = plan_settings;
    fine.lod_pixels = cull.fine_lod_pixels;
    const LodFramePlan whole =
        plan_lod_frame(hierarchy_, banded_view, fine, [](std::size_t) { return true; });
    if (whole.submitted <= cull.fine_points) plan_settings = fine;
  }
  return plan_lod_frame(hierarchy_, banded_view, plan_settings,
                        [&](std::size_t k) { return gpu_->device.count(k) > 0; });
}

std::size_t LodRenderer::upload(const std::vector<std::size_t>& wanted, std::uint64_t byte_limit,
                                LodFrameResult& result) {
  Gpu& gpu = *gpu_;
  std::size_t uploaded = 0;
  std::uint64_t bytes = 0;
  for (const std::size_t node : wanted) {
    if (!gpu.memory->loaded(node) || gpu.device.count(node)) continue;
    const std::span<const lod::LodPoint> points = gpu.memory->points(node);
    const std::uint64_t size = points.size() * kPointBytes;
    if (byte_limit > 0 && uploaded > 0 && bytes + size > byte_limit) break;
    Gpu::DeviceNode held;
    held.buffer = make_buffer();
    held.bytes = std::max<std::uint64_t>(size, kPointBytes);  // GL refuses empty storage
    const lod::LodPoint none{};
    glNamedBufferStorage(held.buffer.get(), static_cast<GLsizeiptr>(held.bytes),
                         points.empty() ? &none : points.data(), 0);
    held.last_frame = gpu.frame;
    gpu.device_bytes += held.bytes;
    gpu.device.emplace(node, std::move(held));
    bytes += size;
    ++uploaded;
  }
  gpu.device_peak = std::max(gpu.device_peak, gpu.device_bytes);
  result.uploaded_nodes += uploaded;
  result.uploaded_bytes += bytes;
  return uploaded;
}

Eigen::Vector3f LodRenderer::node_corner_m(std::size_t k) const {
  const lod::OctreeCube& cube = hierarchy_.header.cube;
  const std::array<std::uint64_t, 3> corner = cube.node_corner(hierarchy_.nodes[k].key);
  Eigen::Vector3f corner_m;
  for (std::size_t c = 0; c < 3; ++c) {
    corner_m[static_cast<int>(c)] = static_cast<float>(
        static_cast<double>(cube.corner[c] + static_cast<std::int64_t>(corner[c])) *
        lod::kQuantumM);
  }
  return corner_m;
}

std::uint32_t LodRenderer::missing_octants(const LodNodeDraw& draw) const {
  // All of them under a prefix, else those with a child that is not drawn.
  if (draw.count < hierarchy_.nodes[draw.node].points) return 0xffu;
  std::uint32_t missing = 0;
  for (int octant = 0; octant < 8; ++octant) {
    const bool child = hierarchy_.children[draw.node][static_cast<std::size_t>(octant)] >= 0;
    if (child && !(draw.children_drawn & (1u << octant))) missing |= 1u << octant;
  }
  return missing;
}

double LodRenderer::issue(const RenderView& banded_view, const RenderSettings& settings,
                          const LodFramePlan& plan) {
  Gpu& gpu = *gpu_;
  const lod::OctreeCube& cube = hierarchy_.header.cube;
  SplatPasses& passes = gpu.passes;
  for (const LodNodeDraw& draw : plan.draws) gpu.device.at(draw.node).last_frame = gpu.frame;
  last_plan_ = plan;
  return passes.draw(banded_view, settings, height_range_, [&] {
    glBindVertexArray(gpu.points.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gpu.objects.get());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, gpu.scans.get());
    for (const LodNodeDraw& draw : plan.draws) {
      const lod::LodNodeInfo& node = hierarchy_.nodes[draw.node];
      const Eigen::Vector3f corner_m = node_corner_m(draw.node);
      const std::uint32_t missing = missing_octants(draw);
      passes.uniform("u_node_corner", corner_m);
      passes.uniform("u_half_edge", static_cast<unsigned>(cube.node_edge(node.key.depth) / 2));
      passes.uniform("u_missing", static_cast<unsigned>(missing));
      passes.uniform("u_cell", draw.cell_m);
      glVertexArrayVertexBuffer(gpu.points.get(), 0, gpu.device.at(draw.node).buffer.get(), 0,
                                static_cast<GLsizei>(kPointBytes));
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(draw.count));
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, 0);
  });
}

void LodRenderer::refuse_failed(const std::vector<std::size_t>& wanted) const {
  for (const std::size_t node : wanted) {
    if (!gpu_->memory->failed(node)) continue;
    // The store's own error, naming the file and the node.
    lod::LodStore::open(store_file_).read_points(hierarchy_.nodes[node].key);
    const auto& failures = gpu_->memory->failures();
    const auto reason = std::find_if(failures.begin(), failures.end(),
                                     [&](const auto& f) { return f.first == node; });
    throw core::RuntimeFailure(store_file_.string(), {},
                               "a node could not be read: " + reason->second);
  }
}

LodFrameResult LodRenderer::draw(const RenderView& picture_view, const RenderSettings& settings,
                                 std::chrono::milliseconds wait_for_nodes) {
  const auto start = std::chrono::steady_clock::now();
  return frame(picture_view, settings, start + wait_for_nodes, limits_.upload_bytes_per_frame);
}

LodFrameResult LodRenderer::draw_complete(const RenderView& picture_view,
                                          const RenderSettings& settings) {
  return frame(picture_view, settings, std::nullopt, 0);
}

LodFrameResult LodRenderer::frame(const RenderView& picture_view, const RenderSettings& settings,
                                  std::optional<std::chrono::steady_clock::time_point> until,
                                  std::uint64_t upload_limit) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const auto ms_since = [](Clock::time_point from) {
    return std::chrono::duration<double, std::milli>(Clock::now() - from).count();
  };
  Gpu& gpu = *gpu_;
  ++gpu.frame;
  const RenderView view = SplatPasses::banded(picture_view);
  LodFrameResult result;
  // The very first frame waits for the root: one node is worth the wait.
  const bool first = gpu.device.empty();
  while (true) {
    gpu.memory->collect(gpu.pending);
    auto lap = Clock::now();
    result.plan = plan(view, settings);
    result.plan_ms += ms_since(lap);
    refuse_failed(result.plan.wanted);
    lap = Clock::now();
    const std::size_t uploaded = upload(result.plan.wanted, upload_limit, result);
    result.upload_ms += ms_since(lap);
    if (uploaded > 0) {
      lap = Clock::now();
      result.plan = plan(view, settings);
      result.plan_ms += ms_since(lap);
    }
    gpu.pending.clear();
    std::vector<std::size_t> missing;
    for (const std::size_t node : result.plan.wanted) {
      (gpu.memory->loaded(node) ? gpu.pending : missing).push_back(node);
    }
    gpu.memory->request(missing);
    if (result.plan.wanted.empty()) break;
    if (first && gpu.device.empty()) {
      gpu.memory->wait_idle();
      continue;
    }
    // Nodes read since could be drawn now: another round while time is left.
    if (until && Clock::now() >= *until) break;
    if (upload_limit > 0 && result.uploaded_bytes >= upload_limit) break;
    if (missing.empty()) continue;  // in memory, waiting for the upload limit of a later round
    if (until) {
      if (!gpu.memory->wait_idle_until(*until)) break;
    } else {
      gpu.memory->wait_idle();
    }
  }
  // Nodes it wants are still being read: a preview within its budget, their
  // requests standing.
  const CullSettings& cull = settings.culling;
  if (!result.plan.wanted.empty() && cull.preview_budget > 0 &&
      (cull.budget == 0 || cull.budget > cull.preview_budget)) {
    RenderSettings preview = settings;
    preview.culling.budget = cull.preview_budget;
    std::vector<std::size_t> wanted = std::move(result.plan.wanted);
    result.plan = plan(view, preview);
    result.plan.wanted = std::move(wanted);
    result.preview = true;
  }
  result.gpu_ms = issue(view, settings, result.plan);
  gpu.evict(limits_.device_bytes);
  result.frame_ms = ms_since(start);
  return result;
}

bool LodRenderer::has_more_to_draw() {
  gpu_->memory->collect(gpu_->pending);
  return std::any_of(last_plan_.wanted.begin(), last_plan_.wanted.end(),
                     [&](std::size_t k) { return gpu_->memory->loaded(k); });
}

void LodRenderer::with_node_points(std::size_t k,
                                   const std::function<void(std::span<const lod::LodPoint>)>& use) {
  if (gpu_->memory->loaded(k)) {
    use(gpu_->memory->points(k));
    return;
  }
  if (!reader_) reader_.emplace(lod::LodStore::open(store_file_));
  use(reader_->read_points(hierarchy_.nodes[k].key));
}

std::optional<LodPick> LodRenderer::pick(const Eigen::Vector3f& origin,
                                         const Eigen::Vector3f& direction,
                                         const RenderSettings& settings) {
  const Clipping& clipping = settings.culling.clipping;
  const float scale = settings.splat_scale;
  // Reach boxes hold each splat's own radius once; drawn, it is scale ×.
  const float grow_factor = std::max(0.0f, scale - 1.0f);
  // Where the ray enters node k's bounds (grown to the drawn splats), when
  // it does and the clipping keeps some of it.
  const auto entry_of = [&](std::size_t k) -> std::optional<float> {
    const Eigen::AlignedBox3f& reach = hierarchy_.reach[k];
    if (reach.isEmpty() || clipping.excludes(reach)) return std::nullopt;
    const float grow = grow_factor * subtree_radius_[k];
    return ray_box_entry(
        Eigen::AlignedBox3f(reach.min().array() - grow, reach.max().array() + grow), origin,
        direction);
  };
  std::optional<LodPick> best;
  // Nodes nearest along the ray first: once a hit is nearer than where the
  // ray enters the next node, no farther node can hold a nearer one.
  using Entry = std::pair<float, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  if (!hierarchy_.nodes.empty() && hierarchy_.nodes.front().key.depth == 0) {
    if (const auto entry = entry_of(0)) queue.emplace(*entry, 0);
  }
  while (!queue.empty()) {
    const auto [entry, k] = queue.top();
    queue.pop();
    if (best && entry >= best->distance_m) break;
    for (const std::int32_t child : hierarchy_.children[k]) {
      if (child < 0) continue;
      if (const auto at = entry_of(static_cast<std::size_t>(child)))
        queue.emplace(*at, static_cast<std::size_t>(child));
    }
    for_each_shown_point(
        k, clipping,
        [&](const lod::LodPoint& q, std::int64_t object, const Eigen::Vector3f& position) {
          SplatShape splat;
          splat.position = position;
          splat.normal = (q.flags & lod::LodPoint::kHasNormal) ? lod::decode_unit(q.normal)
                                                               : Eigen::Vector3f::Zero();
          splat.major_axis = (q.flags & lod::LodPoint::kRound) ? Eigen::Vector3f::Zero()
                                                               : lod::decode_unit(q.major_axis);
          splat.radii_m = Eigen::Vector2f(lod::from_half(q.radii[0]), lod::from_half(q.radii[1]));
          const std::optional<float> hit =
              splat_hit(origin, direction, splat, scale, settings.oriented,
                        best ? best->distance_m : std::numeric_limits<float>::max());
          if (hit) best = LodPick{q, object, splat.position, *hit};
        });
  }
  return best;
}

void LodRenderer::for_each_shown_point(
    std::size_t k, const Clipping& clipping,
    const std::function<void(const lod::LodPoint&, std::int64_t, const Eigen::Vector3f&)>& use) {
  const Eigen::Vector3f corner = node_corner_m(k);
  with_node_points(k, [&](std::span<const lod::LodPoint> points) {
    for (const lod::LodPoint& q : points) {
      const std::int64_t object =
          q.object < object_known_.size() && object_known_[q.object] ? q.object : 0;
      if (!object_shown_[static_cast<std::size_t>(object)]) continue;
      const Eigen::Vector3f position =
          corner + Eigen::Vector3f(static_cast<float>(q.offset[0]), static_cast<float>(q.offset[1]),
                                   static_cast<float>(q.offset[2])) *
                       static_cast<float>(lod::kQuantumM);
      if (clipping.active() && !clipping.keeps(position)) continue;
      use(q, object, position);
    }
  });
}

std::vector<LodSample> LodRenderer::sample(std::size_t count) {
  std::vector<std::size_t> by_depth(hierarchy_.nodes.size());
  std::iota(by_depth.begin(), by_depth.end(), std::size_t{0});
  std::stable_sort(by_depth.begin(), by_depth.end(), [&](std::size_t a, std::size_t b) {
    return hierarchy_.nodes[a].key.depth < hierarchy_.nodes[b].key.depth;
  });
  std::vector<LodSample> out;
  for (const std::size_t k : by_depth) {
    if (out.size() >= count) break;
    const Eigen::Vector3f corner = node_corner_m(k);
    with_node_points(k, [&](std::span<const lod::LodPoint> points) {
      for (const lod::LodPoint& q : points) {
        const Eigen::Vector3f offset(static_cast<float>(q.offset[0]),
                                     static_cast<float>(q.offset[1]),
                                     static_cast<float>(q.offset[2]));
        out.push_back({corner + offset * static_cast<float>(lod::kQuantumM),
                       (q.flags & lod::LodPoint::kHasNormal) ? lod::decode_unit(q.normal)
                                                             : Eigen::Vector3f::Zero(),
                       q.object});
      }
    });
  }
  return out;
}

RenderedImage LodRenderer::read_image() const {
  return gpu_->passes.read_image();
}

PictureTexture LodRenderer::picture_texture() const {
  return gpu_->passes.picture_texture();
}

std::uint64_t LodRenderer::device_bytes() const {
  return gpu_->device_bytes;
}
std::uint64_t LodRenderer::device_peak_bytes() const {
  return gpu_->device_peak;
}
std::uint64_t LodRenderer::memory_peak_bytes() const {
  return gpu_->memory->peak_bytes();
}

}  // namespace scanbench::render

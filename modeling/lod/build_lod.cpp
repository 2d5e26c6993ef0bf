#include "modeling/lod/build_lod.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/lod/parked_points.hpp"
#include "modeling/lod/scan_workers.hpp"
#include "modeling/scan_cache.hpp"

namespace scanbench::lod {
namespace {

// The survey counts points in the cells of this depth (1024 an edge), or
// of the cube's deepest: a chunk is at least one of them.
constexpr int kSurveyDepth = 10;
// What building a chunk takes per point: the point read back (48 bytes),
// its sort order and the radix sort's scratch (16 each), the sorted copy
// and its code (56), the samples drawn from it and the finished nodes.
constexpr std::uint64_t kChunkBytesPerPoint = 256;
// Points a worker collects for a chunk before parking them.
constexpr std::size_t kParkingBatch = 1024;
// Chunks per worker at least, where the model is large enough: work to
// share, whatever the memory allows.
constexpr std::uint64_t kChunksPerWorker = 4;
constexpr std::uint64_t kMinChunkPoints = 1u << 16;

struct Chunk {
  NodeKey key;
  std::uint64_t points = 0;
  Subtree root;  // once built, without its sample (parked)
};

// The survey's counts, sorted by cell, and each cell's chunk.
struct CellCounts {
  int depth = 0;
  std::vector<std::uint64_t> codes;  // Morton codes of the cells at `depth`
  std::vector<std::uint64_t> below;  // points in cells before each; one more entry
  std::vector<std::uint32_t> chunk;

  std::uint64_t total() const { return below.back(); }
};

// Splits the cube into chunks from the survey's counts: a node whose
// region holds at most `chunk_points` points, or is one survey cell, is a
// chunk; the nodes above them are `top`.
class ChunkPlanner {
 public:
  ChunkPlanner(CellCounts& counts, std::uint64_t chunk_points, std::vector<Chunk>& chunks,
               std::vector<NodeKey>& top)
      : counts_(counts), chunk_points_(chunk_points), chunks_(chunks), top_(top) {}

  void plan(const NodeKey& node, std::size_t begin, std::size_t end) {
    const std::uint64_t points = counts_.below[end] - counts_.below[begin];
    if (points <= chunk_points_ || node.depth == counts_.depth) {
      for (std::size_t k = begin; k < end; ++k)
        counts_.chunk[k] = static_cast<std::uint32_t>(chunks_.size());
      chunks_.push_back({node, points, {}});
      return;
    }
    top_.push_back(node);
    for_each_octant_run(
        counts_.codes, begin, end, 3 * (counts_.depth - node.depth - 1),
        [&](int octant, std::size_t b, std::size_t e) { plan(node.child(octant), b, e); });
  }

 private:
  CellCounts& counts_;
  std::uint64_t chunk_points_;
  std::vector<Chunk>& chunks_;
  std::vector<NodeKey>& top_;
};

// The model's origin: the first scanner, rounded to metres (as the render
// model's), so floats relative to it keep sub-millimetre precision.
Eigen::Vector3d model_origin(const std::vector<store::StoredScanSummary>& scans) {
  return scans.front().summary.T_world_scan.translation().array().round();
}

// The cube on the scans' bounds, grown by their extent on every side.
// Refuses a scan whose bounds are not
// finite or lie so far that the cube would pass 2^32 quanta (429 km): a
// wrong pose or range, which the store's 32-bit positions cannot hold.
OctreeCube model_cube(const store::Project& project,
                      const std::vector<store::StoredScanSummary>& scans,
                      const Eigen::Vector3d& origin) {
  constexpr double kFarthestM = 2e5;
  Eigen::AlignedBox3d box;
  for (const store::StoredScanSummary& s : scans) {
    if (!s.summary.bbox_world) continue;
    const Eigen::AlignedBox3d own(s.summary.bbox_world->min() - origin,
                                  s.summary.bbox_world->max() - origin);
    if (!own.min().allFinite() || !own.max().allFinite() ||
        own.min().cwiseAbs().maxCoeff() > kFarthestM ||
        own.max().cwiseAbs().maxCoeff() > kFarthestM) {
      refuse_scan(project, s,
                  "has points more than 200 km from the first scanner: check its pose "
                  "(`scanbench info`)");
    }
    box.extend(own);
  }
  // Room for the campaign to grow: a scan added later whose bounds reach
  // at most the model's extent beyond them is inserted in place
  // (update_lod.hpp). It costs the tree a level or two above the model.
  if (!box.isEmpty()) {
    constexpr double kLargestEdgeM = 4e5;  // within the 2^32 quanta of a position
    const Eigen::Vector3d extent = box.sizes();
    const double room = std::max(0.0, (kLargestEdgeM - extent.maxCoeff()) / 2.0);
    const Eigen::Vector3d grow = extent.cwiseMin(room);
    box.extend(box.min() - grow);
    box.extend(box.max() + grow);
  }
  return OctreeCube::enclosing(box);
}

// Routes one worker's points to their chunks: collected a thousand a chunk
// at a time, then parked.
class ChunkRouter {
 public:
  ChunkRouter(const OctreeCube& cube, const CellCounts& counts, ParkedPoints& parked,
              std::size_t chunks)
      : cube_(cube), counts_(counts), parked_(parked), waiting_(chunks) {}

  void add(std::span<const BuildPoint> points) {
    for (const BuildPoint& p : points) {
      // Neighbours in a scan's rows mostly share a cell: the last one's
      // chunk is looked up again only when the cell changes.
      const std::uint64_t code = cube_.morton_of(p.point.offset, counts_.depth);
      if (code != last_code_) {
        const auto at = std::lower_bound(counts_.codes.begin(), counts_.codes.end(), code);
        assert(at != counts_.codes.end() && *at == code && "the survey counted every cell");
        last_code_ = code;
        last_chunk_ = counts_.chunk[static_cast<std::size_t>(at - counts_.codes.begin())];
      }
      const std::uint32_t chunk = last_chunk_;
      waiting_[chunk].push_back(p);
      if (waiting_[chunk].size() >= kParkingBatch) park(chunk);
    }
  }

  void finish() {
    for (std::size_t chunk = 0; chunk < waiting_.size(); ++chunk) park(chunk);
  }

 private:
  void park(std::size_t chunk) {
    parked_.add(chunk, waiting_[chunk]);
    waiting_[chunk].clear();
  }

  const OctreeCube& cube_;
  const CellCounts& counts_;
  ParkedPoints& parked_;
  std::vector<std::vector<BuildPoint>> waiting_;
  std::uint64_t last_code_ = ~std::uint64_t{0};  // no cell's
  std::uint32_t last_chunk_ = 0;
};

// Builds the nodes above the chunks from the chunks' roots, depth first.
class TopBuilder {
 public:
  TopBuilder(const OctreeCube& cube, std::vector<Chunk>& chunks, const std::vector<NodeKey>& top,
             ParkedPoints& roots, LodStoreWriter& writer)
      : cube_(cube), chunks_(chunks), roots_(roots), writer_(writer) {
    for (const NodeKey& key : top) top_.insert(key.code());
    for (std::size_t k = 0; k < chunks_.size(); ++k) chunk_of_.emplace(chunks_[k].key.code(), k);
  }

  Subtree build(const NodeKey& key) {
    if (const auto chunk = chunk_of_.find(key.code()); chunk != chunk_of_.end()) {
      Subtree node = std::move(chunks_[chunk->second].root);
      node.sample = roots_.take(chunk->second);
      return node;
    }
    Subtree node;
    node.key = key;
    std::vector<Subtree> children;
    for (int octant = 0; octant < 8; ++octant) {
      const NodeKey child = key.child(octant);
      if (top_.count(child.code()) || chunk_of_.count(child.code()))
        children.push_back(build(child));
    }
    draw_from_children(cube_, node, children);
    for (Subtree& child : children) writer_.put(finish_node(cube_, std::move(child)));
    return node;
  }

 private:
  const OctreeCube& cube_;
  std::vector<Chunk>& chunks_;
  ParkedPoints& roots_;
  LodStoreWriter& writer_;
  std::unordered_set<std::uint64_t> top_;
  std::unordered_map<std::uint64_t, std::size_t> chunk_of_;
};

std::uint64_t chunk_points_for(const LodBuildSettings& settings, std::uint64_t limit, int workers,
                               std::uint64_t total) {
  if (settings.chunk_points > 0) return settings.chunk_points;
  const auto w = static_cast<std::uint64_t>(workers);
  const std::uint64_t fit = limit / (kChunkBytesPerPoint * w);
  const std::uint64_t shared = std::max(kMinChunkPoints, total / (kChunksPerWorker * w));
  return std::clamp<std::uint64_t>(std::min(fit, shared), kMinChunkPoints, 1u << 23);
}

}  // namespace

// Longer than 60 lines, but flat: the five phases in order, sharing the
// counts, chunks and parked points.
LodBuildResult build_lod(const store::Project& project, const LodBuildSettings& settings,
                         core::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto lap_start = start;
  // Seconds since the last lap.
  const auto lap = [&lap_start] {
    const auto now = std::chrono::steady_clock::now();
    return std::chrono::duration<double>(now - std::exchange(lap_start, now)).count();
  };
  const store::Project::ReadSnapshot snapshot = project.read_snapshot();
  const std::vector<store::StoredScanSummary> scans = modeling::scans_with_geometry(project);
  if (scans.size() > std::size_t{std::numeric_limits<std::uint16_t>::max()} + 1) {
    refuse_scan(project, scans[65536], "is one scan more than a store holds (65 536)");
  }
  LodBuildResult result;
  result.store = settings.output.empty() ? LodStore::path_for(project.path()) : settings.output;
  result.project_revision = project.revision();
  result.scans = scans.size();
  result.threads = core::worker_count(settings.threads);
  const std::uint64_t limit = modeling::memory_limit_or_default(settings.memory_limit_bytes);

  LodHeader header;
  header.project_revision = result.project_revision;
  header.origin = model_origin(scans);
  header.cube = model_cube(project, scans, header.origin);
  header.octree = settings.octree;
  const OctreeCube& cube = header.cube;

  // 1. Survey, a scan per worker.
  CellCounts counts;
  counts.depth = std::min(kSurveyDepth, cube.max_depth());
  std::vector<LodScan> lod_scans(scans.size());
  {
    std::unordered_map<std::uint64_t, std::uint64_t> cells;
    std::mutex merging;
    for_each_scan(project, result.project_revision, scans, every_scan(scans), result.threads,
                  progress, "lod: survey", [&](std::size_t s, const store::Project& own_project) {
                    std::unordered_map<std::uint64_t, std::uint64_t> own;
                    const ScanSurvey survey = survey_scan(
                        own_project, scans[s], cube, header.origin, settings.points,
                        [&](std::span<const std::array<std::uint32_t, 3>> positions) {
                          // Runs of a cell (neighbours in a row mostly share one) count at once.
                          for (std::size_t i = 0; i < positions.size();) {
                            const std::uint64_t code = cube.morton_of(positions[i], counts.depth);
                            std::size_t end = i + 1;
                            while (end < positions.size() &&
                                   cube.morton_of(positions[end], counts.depth) == code)
                              ++end;
                            own[code] += end - i;
                            i = end;
                          }
                        });
                    const ScanSources sources = scan_sources(own_project, scans[s].id);
                    lod_scans[s] = {static_cast<std::uint16_t>(s),
                                    scans[s].id,
                                    scans[s].summary.name,
                                    survey.intensity_low,
                                    survey.intensity_high,
                                    scans[s].summary.T_world_scan,
                                    sources.points,
                                    sources.owners,
                                    survey.band_rows,
                                    scans[s].summary.columns,
                                    scan_points_content(own_project, scans[s].id)};
                    const std::lock_guard lock(merging);
                    for (const auto& [code, n] : own) cells[code] += n;
                    result.in_model += survey.in_model;
                    result.merged_away += survey.merged_away;
                    result.deleted += survey.deleted;
                  });
    std::vector<std::pair<std::uint64_t, std::uint64_t>> sorted(cells.begin(), cells.end());
    std::sort(sorted.begin(), sorted.end());
    counts.below.push_back(0);
    for (const auto& [code, n] : sorted) {
      counts.codes.push_back(code);
      counts.below.push_back(counts.below.back() + n);
    }
    counts.chunk.assign(counts.codes.size(), 0);
  }
  result.survey_seconds = lap();

  // 2. Chunks.
  std::vector<Chunk> chunks;
  std::vector<NodeKey> top;
  if (!counts.codes.empty()) {
    // A node above the chunks is an inner node: it must hold more than a
    // leaf may, or the chunks would cut the tree elsewhere than the model
    // in memory does.
    const std::uint64_t chunk_points =
        std::max<std::uint64_t>(chunk_points_for(settings, limit, result.threads, counts.total()),
                                settings.octree.max_leaf_points);
    ChunkPlanner(counts, chunk_points, chunks, top).plan({}, 0, counts.codes.size());
  }
  // Points wait in memory when the model takes at most half the limit.
  const bool in_memory = counts.total() * sizeof(BuildPoint) <= limit / 2;
  const std::uint64_t waiting = in_memory ? counts.total() * sizeof(BuildPoint) : 0;
  std::uint64_t largest = 0;
  for (const Chunk& chunk : chunks) largest = std::max(largest, chunk.points);
  core::check_memory_limit(
      waiting + largest * kChunkBytesPerPoint, limit, project.path().string(), "lod",
      "the densest part of the model (" + std::to_string(largest) + " points in one cell)");
  // As many chunks at once as the limit holds, at most one a worker.
  const int chunk_workers = static_cast<int>(std::clamp<std::uint64_t>(
      (limit - waiting) / std::max<std::uint64_t>(1, largest * kChunkBytesPerPoint), 1,
      static_cast<std::uint64_t>(result.threads)));
  result.chunks = chunks.size();

  // 3. Distribute, a scan per worker, storing each band's owners.
  LodStoreWriter writer(result.store, header, lod_scans);
  ParkedPoints parked(chunks.size(), in_memory);
  for (std::size_t c = 0; c < chunks.size(); ++c) parked.reserve(c, chunks[c].points);
  for_each_scan(project, result.project_revision, scans, every_scan(scans), result.threads,
                progress, "lod: distribute", [&](std::size_t s, const store::Project& own_project) {
                  ChunkRouter router(cube, counts, parked, chunks.size());
                  const LodScan& scan = lod_scans[s];
                  std::vector<BuildPoint> points;
                  read_shown_bands(own_project, scans[s], scan, cube, header.origin,
                                   settings.points, [&](const ShownBand& band) {
                                     if (points.capacity() < band.owners.size())
                                       core::reserve_mapped(points, band.owners.size());
                                     points.clear();
                                     for (std::size_t g = 0; g < band.owners.size(); ++g) {
                                       if (in_store(band.owners[g]))
                                         points.push_back(band.point(g));
                                     }
                                     router.add(points);
                                     writer.put_owners(scan.index,
                                                       band.first_row / scan.digest_rows,
                                                       band.owners);
                                   });
                  router.finish();
                });
  result.distribute_seconds = lap();

  // 4. Chunks, at most one a worker at a time; their roots wait.
  ParkedPoints roots(chunks.size(), in_memory);
  for_each_item(
      chunks.size(), chunk_workers, progress, "lod: build", [](std::size_t) { return ""; },
      [&](std::size_t c) {
        Subtree root = build_subtree(cube, chunks[c].key, parked.take(c), settings.octree,
                                     [&](BuiltNode&& node) { writer.put(node); });
        roots.add(c, root.sample);
        root.sample = {};
        chunks[c].root = std::move(root);
      });
  result.chunk_seconds = lap();

  // 5. The nodes above the chunks, and the root.
  progress.throw_if_cancelled("lod");
  if (!chunks.empty()) {
    TopBuilder builder(cube, chunks, top, roots, writer);
    writer.put(finish_node(cube, builder.build({})));
  }
  writer.commit();
  result.top_seconds = lap();
  result.points = writer.points();
  result.nodes = writer.nodes();
  std::error_code error;
  result.store_bytes = std::filesystem::file_size(result.store, error);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::optional<std::filesystem::path> current_lod_store(const store::Project& project) {
  const std::filesystem::path file = LodStore::path_for(project.path());
  if (!std::filesystem::exists(file)) return std::nullopt;
  std::int64_t reflects = 0;
  try {
    reflects = LodStore::open(file).header().project_revision;
  } catch (const core::InputError&) {  // damaged or of another format: built again
    return std::nullopt;
  }
  for (const store::ProjectData data : store::data_in(kLodInputs)) {
    if (project.changed_at(data) > reflects) return std::nullopt;
  }
  return file;
}

}  // namespace scanbench::lod

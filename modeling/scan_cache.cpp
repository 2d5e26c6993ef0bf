#include "modeling/scan_cache.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <type_traits>
#include <utility>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

constexpr std::size_t kNever = std::numeric_limits<std::size_t>::max();

// Before the first load: a scan with colour, intensity, geometry and its
// prepared view takes about this much per pixel; later loads use the most
// measured (before a stage's form trims it).
constexpr double kFirstBytesPerPixel = 64.0;
// A point index (kd-tree of a grid without a spherical model) per point.
constexpr std::size_t kIndexBytesPerPoint = 32;

// Calls visit(v) for every per-pixel array of `loaded` (a LoadedScan,
// const or not), always in the same order (the spill's).
template <typename Loaded, typename Visit>
void visit_arrays(Loaded& loaded, Visit&& visit) {
  auto& s = loaded.scan;
  visit(s.range_m);
  visit(s.valid);
  visit(s.intensity);
  visit(s.rgb);
  if (auto* per_pixel = std::get_if<acquisition::PerPixelDirections>(&s.angles))
    visit(per_pixel->directions);
  auto& g = loaded.geometry;
  visit(g.footprint_m);
  visit(g.normal);
  visit(g.confidence);
  visit(g.flags);
  auto& p = loaded.prepared;
  visit(p.points);
  visit(p.in_model);
  visit(p.usable);
  visit(p.sample_area_m2);
}

std::size_t heap_bytes_of(const LoadedScan& loaded) {
  std::size_t bytes = 0;
  visit_arrays(loaded, [&bytes](auto& v) { bytes += v.capacity() * sizeof(v[0]); });
  if (loaded.prepared.tree) bytes += kIndexBytesPerPoint * loaded.prepared.points.size();
  return bytes;
}

template <typename T>
void release(std::vector<T>& v) {
  v.clear();
  v.shrink_to_fit();
}

// Drops what a stage of `form` does not read, of what it loaded (it was
// needed to prepare the scan).
void trim_to(ScanForm form, LoadedScan& loaded) {
  if (form != ScanForm::kMerge) return;
  release(loaded.scan.valid);
  release(loaded.geometry.confidence);
  release(loaded.geometry.flags);
}

}  // namespace

std::uint64_t memory_limit_or_default(std::optional<std::uint64_t> requested) {
  if (requested) return *requested;
  constexpr std::uint64_t kUnknown = std::uint64_t{4} << 30;
  const std::optional<std::uint64_t> available = core::available_memory_bytes();
  return available ? *available / 4 * 3 : kUnknown;
}

std::vector<store::StoredScanSummary> scans_with_geometry(const store::Project& project) {
  std::vector<store::StoredScanSummary> scans = project.scans();
  if (scans.empty())
    throw core::InputError(project.path().string(), {}, "the project has no scans");
  for (const store::StoredScanSummary& stored : scans) {
    const std::vector<std::string> layers = project.layer_names(stored.id);
    if (std::find(layers.begin(), layers.end(), store::layer::kNormal) == layers.end()) {
      throw core::InputError(project.path().string(), {},
                             "scan " + std::to_string(stored.id) + " (" + stored.summary.name +
                                 ") has no geometry: run scanbench geometry first");
    }
  }
  return scans;
}

ScanCache::ScanCache(const store::Project& project, std::uint64_t memory_limit_bytes, int threads,
                     std::string stage, core::Progress& progress, ScanCacheSettings settings)
    : project_(project),
      limit_(memory_limit_bytes),
      threads_(threads),
      stage_(std::move(stage)),
      progress_(progress),
      settings_(settings),
      bytes_per_pixel_(kFirstBytesPerPixel) {
  if (settings_.spill) spill_ = std::make_unique<core::SpillFile>();
  for (const store::StoredScanSummary& stored : project_.scans()) {
    pixels_[stored.id] = static_cast<std::size_t>(stored.summary.rows) *
                         static_cast<std::size_t>(stored.summary.columns);
  }
}

void ScanCache::plan(std::vector<std::int64_t> order) {
  plan_ = std::move(order);
  position_ = 0;
  next_use_.assign(plan_.size(), kNever);
  std::map<std::int64_t, std::size_t> later;
  for (std::size_t k = plan_.size(); k-- > 0;) {
    const auto found = later.find(plan_[k]);
    if (found != later.end()) next_use_[k] = found->second;
    later[plan_[k]] = k;
  }
  for (auto it = kept_.begin(); it != kept_.end();) {
    const auto first = later.find(it->first);
    if (first == later.end()) {
      it = kept_.erase(it);
    } else {
      it->second.next_use = first->second;
      ++it;
    }
  }
  std::vector<std::int64_t> unnamed;
  for (const auto& [id, parked] : parked_)
    if (!later.contains(id)) unnamed.push_back(id);
  for (const std::int64_t id : unnamed) unpark(id);
}

void CachedScans::plan(std::vector<int> order) {
  std::vector<std::int64_t> ids;
  ids.reserve(order.size());
  for (const int k : order) ids.push_back(ids_[static_cast<std::size_t>(k)]);
  cache_.plan(std::move(ids));
}

std::shared_ptr<const registration::PreparedScan> CachedScans::get(int k) {
  std::shared_ptr<const LoadedScan> loaded = cache_.get(ids_[static_cast<std::size_t>(k)]);
  const registration::PreparedScan* prepared = &loaded->prepared;
  return {std::move(loaded), prepared};
}

std::uint64_t ScanCache::bytes_in_hand() const {
  std::uint64_t bytes = 0;
  for (const std::weak_ptr<const LoadedScan>& given : given_) {
    if (const std::shared_ptr<const LoadedScan> scan = given.lock()) bytes += scan->bytes;
  }
  return bytes;
}

// The kept scan the stage does not hold whose next use is farthest away
// (kept_.end() when it holds them all), and how many it does not hold.
std::pair<std::map<std::int64_t, ScanCache::Entry>::iterator, std::size_t>
ScanCache::farthest_unheld() {
  std::size_t unheld = 0;
  auto farthest = kept_.end();
  for (auto it = kept_.begin(); it != kept_.end(); ++it) {
    if (it->second.scan.use_count() > 1) continue;  // held by the stage
    ++unheld;
    if (farthest == kept_.end() || it->second.next_use > farthest->second.next_use) farthest = it;
  }
  return {farthest, unheld};
}

// Drops kept scans, farthest next use first, until `bytes` more fit under
// the limit or only held scans are left.
void ScanCache::make_room(std::uint64_t bytes) {
  std::erase_if(given_, [](const auto& given) { return given.expired(); });
  while (bytes_in_hand() + bytes > limit_) {
    const auto farthest = farthest_unheld().first;
    if (farthest == kept_.end()) return;
    drop(farthest);
  }
}

// Lets a kept scan go, parking it first when the plan brings it back.
void ScanCache::drop(std::map<std::int64_t, Entry>::iterator kept) {
  if (kept->second.next_use != kNever) park(*kept->second.scan);
  kept_.erase(kept);
}

// Drops kept scans the stage does not hold, farthest next use first, until
// at most `count` are left.
void ScanCache::keep_at_most(std::size_t count) {
  while (true) {
    const auto [farthest, unheld] = farthest_unheld();
    if (unheld <= count) return;
    drop(farthest);
  }
}

// Throws core::MemoryShortage when `bytes` (the scans in hand with scan
// `id`) exceed the limit.
void ScanCache::refuse_beyond_limit(std::uint64_t bytes, std::int64_t id) const {
  core::check_memory_limit(
      bytes, limit_, project_.path().string(), stage_,
      "the scans it works on together (scan " + std::to_string(id) + " and those in hand)");
}

std::shared_ptr<LoadedScan> ScanCache::load_from_project(std::int64_t id) const {
  auto loaded = std::make_shared<LoadedScan>();
  loaded->id = id;
  std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project_, id);
  if (!geometry) {
    throw core::InputError(
        project_.path().string(), {},
        "scan " + std::to_string(id) + " has no geometry: run scanbench geometry first");
  }
  loaded->geometry = std::move(*geometry);
  const bool whole = settings_.form == ScanForm::kWhole;
  loaded->scan = project_.load_scan(id, {.intensity = whole, .color = whole});
  loaded->prepared = registration::prepare_scan(loaded->scan, loaded->geometry, threads_,
                                                settings_.form == ScanForm::kMerge
                                                    ? registration::GridPoints::kLeftOut
                                                    : registration::GridPoints::kComputed);
  return loaded;
}

// Writes the arrays of `loaded` to the spill, unless they are there
// already or it cannot take them all.
void ScanCache::park(const LoadedScan& loaded) {
  if (spill_ == nullptr || !spill_->usable() || parked_.contains(loaded.id)) return;
  Parked parked{acquisition::without_arrays(loaded.scan), loaded.geometry.range_noise, {}};
  visit_arrays(loaded, [&](auto& v) {
    if (const std::optional<core::SpillFile::Extent> extent =
            spill_->put(v.data(), v.size() * sizeof(v[0]))) {
      parked.arrays.push_back(*extent);
    }
  });
  if (spill_->usable()) {
    parked_.emplace(loaded.id, std::move(parked));
  } else {
    // The file failed a write (a full disk): what it took of this scan is
    // given back, and the scan will be loaded from the project again.
    for (const core::SpillFile::Extent& extent : parked.arrays) spill_->release(extent);
  }
}

// Gives the spill's space of scan `id` back: the plan is done with it.
void ScanCache::unpark(std::int64_t id) {
  const auto parked = parked_.find(id);
  if (parked == parked_.end()) return;
  for (const core::SpillFile::Extent& extent : parked->second.arrays) spill_->release(extent);
  parked_.erase(parked);
}

// The scan `parked` describes, its arrays read back from the spill; the
// same as when it was parked.
std::shared_ptr<LoadedScan> ScanCache::read_back(const Parked& parked, std::int64_t id) const {
  auto loaded = std::make_shared<LoadedScan>();
  loaded->id = id;
  loaded->scan = parked.scan;
  loaded->geometry.range_noise = parked.range_noise;
  std::size_t k = 0;
  visit_arrays(*loaded, [&](auto& v) {
    const core::SpillFile::Extent& extent = parked.arrays[k++];
    using T = typename std::remove_reference_t<decltype(v)>::value_type;
    core::reserve_mapped(v, extent.bytes / sizeof(T));
    v.resize(extent.bytes / sizeof(T));
    spill_->get(extent, v.data());
  });
  registration::PreparedScan& prepared = loaded->prepared;
  prepared.scan = &loaded->scan;
  prepared.geometry = &loaded->geometry;
  if (loaded->scan.is_spherical()) {
    prepared.grid.emplace(loaded->scan);
  } else {
    prepared.tree = std::make_unique<registration::PointIndex>(prepared.points, prepared.usable);
  }
  return loaded;
}

std::shared_ptr<const LoadedScan> ScanCache::load(std::int64_t id) {
  // A scan the stage still holds from an earlier plan is not loaded twice.
  for (const std::weak_ptr<const LoadedScan>& given : given_) {
    if (std::shared_ptr<const LoadedScan> held = given.lock(); held && held->id == id) return held;
  }
  const auto pixels = pixels_.find(id);
  if (pixels == pixels_.end())
    throw core::InputError(project_.path().string(), {}, "no scan with id " + std::to_string(id));
  keep_at_most(settings_.max_kept);  // scans let go since the last get
  // A scan read back takes what was parked (and its index); one loaded
  // from the project takes its whole form until it is trimmed.
  const auto parked = parked_.find(id);
  std::uint64_t estimate = 0;
  if (parked != parked_.end()) {
    for (const core::SpillFile::Extent& extent : parked->second.arrays) estimate += extent.bytes;
    if (!parked->second.scan.is_spherical()) estimate += kIndexBytesPerPoint * pixels->second;
  } else {
    estimate = static_cast<std::uint64_t>(bytes_per_pixel_ * static_cast<double>(pixels->second));
  }
  make_room(estimate);
  refuse_beyond_limit(bytes_in_hand() + estimate, id);
  std::shared_ptr<LoadedScan> loaded;
  if (parked != parked_.end()) {
    loaded = read_back(parked->second, id);
    ++spill_reads_;
  } else {
    loaded = load_from_project(id);
    const std::size_t whole = heap_bytes_of(*loaded);
    if (pixels->second > 0) {
      bytes_per_pixel_ = std::max(bytes_per_pixel_,
                                  static_cast<double>(whole) / static_cast<double>(pixels->second));
    }
    trim_to(settings_.form, *loaded);
    ++loads_;
  }
  loaded->bytes = heap_bytes_of(*loaded);
  given_.emplace_back(loaded);
  // The estimate may have been short (the first one, a kd-tree): the limit
  // holds for what was really loaded.
  make_room(0);
  const std::uint64_t in_hand = bytes_in_hand();
  refuse_beyond_limit(in_hand, id);
  peak_bytes_ = std::max(peak_bytes_, in_hand);
  return loaded;
}

std::shared_ptr<const LoadedScan> ScanCache::get(std::int64_t id) {
  assert(position_ < plan_.size() && plan_[position_] == id && "get() follows the plan");
  const std::size_t next = next_use_[position_++];
  progress_.throw_if_cancelled(stage_);
  std::shared_ptr<const LoadedScan> scan;
  if (const auto found = kept_.find(id); found != kept_.end()) {
    scan = found->second.scan;
  } else {
    scan = load(id);
  }
  if (next == kNever) {
    kept_.erase(id);  // the stage is its last holder
    unpark(id);
  } else {
    kept_[id] = {scan, next};
  }
  keep_at_most(settings_.max_kept);
  return scan;
}

}  // namespace scanbench::modeling

#include "render/lod_node_cache.hpp"

#include <algorithm>
#include <cassert>
#include <iterator>
#include <optional>

#include "core/errors.hpp"
#include "modeling/lod/lod_store.hpp"

namespace scanbench::render {

LodNodeCache::LodNodeCache(std::filesystem::path store, std::vector<lod::NodeKey> keys,
                           std::uint64_t byte_limit)
    : store_(std::move(store)),
      keys_(std::move(keys)),
      byte_limit_(byte_limit),
      failed_(keys_.size(), 0),
      loader_([this] { load_loop(); }) {}

LodNodeCache::~LodNodeCache() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  loader_.join();
}

void LodNodeCache::request(const std::vector<std::size_t>& wanted) {
  std::vector<std::size_t> queue;
  for (auto at = wanted.rbegin(); at != wanted.rend(); ++at) {
    if (!loaded(*at) && !failed_[*at]) queue.push_back(*at);
  }
  {
    const std::lock_guard lock(mutex_);
    queue_ = std::move(queue);
  }
  wake_.notify_one();
}

std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> LodNodeCache::release() {
  std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> out;
  for (const std::size_t node : use_) out.emplace_back(node, std::move(resident_.at(node).points));
  resident_.clear();
  use_.clear();
  bytes_ = 0;
  return out;
}

void LodNodeCache::adopt(std::size_t node, std::vector<lod::LodPoint> points) {
  if (loaded(node)) return;
  bytes_ += points.size() * sizeof(lod::LodPoint);
  peak_bytes_ = std::max(peak_bytes_, bytes_);
  use_.push_back(node);
  resident_.emplace(node, Resident{std::move(points), std::prev(use_.end())});
}

std::vector<std::size_t> LodNodeCache::collect(std::span<const std::size_t> in_use) {
  std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> ready;
  {
    const std::lock_guard lock(mutex_);
    ready.swap(ready_);
    for (auto& failure : new_failures_) {
      failed_[failure.first] = 1;
      failures_.push_back(std::move(failure));
    }
    new_failures_.clear();
  }
  std::vector<std::size_t> taken;
  for (auto& [node, points] : ready) {
    if (loaded(node)) continue;
    bytes_ += points.size() * sizeof(lod::LodPoint);
    use_.push_front(node);
    resident_.emplace(node, Resident{std::move(points), use_.begin()});
    taken.push_back(node);
  }
  for (const std::size_t node : in_use) {
    const auto found = resident_.find(node);
    if (found != resident_.end()) use_.splice(use_.begin(), use_, found->second.use);
  }
  peak_bytes_ = std::max(peak_bytes_, bytes_);
  // The least recently used go first; those in use stay, over the limit if
  // the frame needs them all.
  const std::size_t keep_at_least = in_use.size();
  while (bytes_ > byte_limit_ && use_.size() > keep_at_least) {
    const std::size_t node = use_.back();
    if (std::find(in_use.begin(), in_use.end(), node) != in_use.end()) break;
    use_.pop_back();
    bytes_ -= resident_.at(node).points.size() * sizeof(lod::LodPoint);
    resident_.erase(node);
  }
  return taken;
}

std::span<const lod::LodPoint> LodNodeCache::points(std::size_t node) {
  Resident& resident = resident_.at(node);
  use_.splice(use_.begin(), use_, resident.use);
  return resident.points;
}

bool LodNodeCache::busy() const {
  const std::lock_guard lock(mutex_);
  return !queue_.empty() || loading_ != SIZE_MAX;
}

void LodNodeCache::wait_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && loading_ == SIZE_MAX; });
}

bool LodNodeCache::wait_idle_until(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return idle_.wait_until(lock, deadline,
                          [this] { return queue_.empty() && loading_ == SIZE_MAX; });
}

void LodNodeCache::load_loop() {
  std::optional<lod::LodStore> store;
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    loading_ = queue_.back();
    queue_.pop_back();
    const std::size_t node = loading_;
    lock.unlock();
    std::vector<lod::LodPoint> points;
    std::string failure;
    try {
      if (!store) store.emplace(lod::LodStore::open(store_));
      points = store->read_points(keys_[node]);
    } catch (const std::exception& e) {  // a damaged node, a store gone, no memory
      failure = e.what();
    }
    lock.lock();
    if (failure.empty()) {
      ready_.emplace_back(node, std::move(points));
    } else {
      new_failures_.emplace_back(node, std::move(failure));
    }
    loading_ = SIZE_MAX;
    if (queue_.empty()) idle_.notify_all();
  }
}

}  // namespace scanbench::render

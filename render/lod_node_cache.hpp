// The nodes of a level-of-detail store in main memory (seed 000 §4: a
// loader thread streams nodes from disk by priority into an LRU cache with
// a byte limit). The render thread asks for the nodes a frame wants, most
// important first; the loader reads them on its own connection to the
// store; the render thread takes them in between frames and lets the least
// recently drawn go beyond the limit, never one the last frame drew.
//
// Every member but the loader's own runs on one thread, the render
// thread's; the spans points() gives stay valid until the next collect().
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "modeling/lod/lod_point.hpp"
#include "modeling/lod/octree_cube.hpp"

namespace scanbench::render {

class LodNodeCache {
 public:
  // Nodes of the store at `store`, named by their index in `keys` (a
  // LodHierarchy's order); at most `byte_limit` bytes of points kept.
  LodNodeCache(std::filesystem::path store, std::vector<lod::NodeKey> keys,
               std::uint64_t byte_limit);
  ~LodNodeCache();  // stops the loader
  LodNodeCache(const LodNodeCache&) = delete;
  LodNodeCache& operator=(const LodNodeCache&) = delete;

  // The nodes to load next, most important first: replaces what was asked
  // before and is not yet loading. Nodes in memory or failed are skipped.
  void request(const std::vector<std::size_t>& wanted);

  // Takes in what the loader read since the last call, then lets the
  // least recently used nodes go until the cache is within its limit,
  // keeping those in `in_use` (the frame's draws). Returns the nodes taken
  // in (for an upload to the GPU).
  std::vector<std::size_t> collect(std::span<const std::size_t> in_use);

  bool loaded(std::size_t node) const { return resident_.count(node) > 0; }
  // The nodes in memory, most recently used first, given up (the cache is
  // then empty): a renderer following an update hands those the update
  // left alone to the cache of the new hierarchy (adopt).
  std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> release();
  // Takes node `node`'s points in as if the loader had read them, least
  // recently used (adopt the most recent first); ignored when it is in
  // memory already.
  void adopt(std::size_t node, std::vector<lod::LodPoint> points);
  // The points of a node in memory (asserted), marking it used now.
  std::span<const lod::LodPoint> points(std::size_t node);

  std::uint64_t bytes() const { return bytes_; }
  std::uint64_t peak_bytes() const { return peak_bytes_; }
  // Nodes the loader could not read, with the reason (a damaged node, a
  // store gone): never asked for again.
  const std::vector<std::pair<std::size_t, std::string>>& failures() const { return failures_; }
  bool failed(std::size_t node) const { return failed_[node] != 0; }
  // True while the loader has nodes queued or in hand.
  bool busy() const;
  // Waits until the loader is idle (a picture that must be complete, tests).
  void wait_idle();
  // The same, giving up at `deadline`; whether it is idle.
  bool wait_idle_until(std::chrono::steady_clock::time_point deadline);

 private:
  struct Resident {
    std::vector<lod::LodPoint> points;
    std::list<std::size_t>::iterator use;  // its place in use_, most recent first
  };
  void load_loop();

  std::filesystem::path store_;
  std::vector<lod::NodeKey> keys_;
  std::uint64_t byte_limit_;
  // The render thread's.
  std::unordered_map<std::size_t, Resident> resident_;
  std::list<std::size_t> use_;
  std::uint64_t bytes_ = 0, peak_bytes_ = 0;
  std::vector<std::pair<std::size_t, std::string>> failures_;
  std::vector<char> failed_;
  // Shared with the loader, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::vector<std::size_t> queue_;  // most important last (taken from the back)
  std::size_t loading_ = SIZE_MAX;  // the node in the loader's hands
  std::vector<std::pair<std::size_t, std::vector<lod::LodPoint>>> ready_;
  std::vector<std::pair<std::size_t, std::string>> new_failures_;
  bool stop_ = false;
  std::thread loader_;
};

}  // namespace scanbench::render

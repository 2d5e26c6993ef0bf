// The sample clouds of a registration's scans, one a scan, with only the
// few in use in memory: every cloud is parked in a temporary file
// (core::SpillFile) as it is put, and read back when asked for after it
// has left memory. So a registration holds the samples of the scans at
// hand, not of the whole campaign (a scan's ICP samples take up to 1.3 MB).
// Where the file cannot take a cloud, that cloud stays in memory.
// Not thread-safe: one stage's thread puts and gets.
#pragma once

#include <cassert>
#include <cstddef>
#include <list>
#include <memory>
#include <vector>

#include "core/spill_file.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

class SampleShelf {
 public:
  // `scans` empty slots; besides the clouds handed out and still held, at
  // most `kept` stay in memory (the ones used last; 0: none).
  explicit SampleShelf(std::size_t scans, std::size_t kept = 16);

  std::size_t size() const { return slots_.size(); }

  // Puts the cloud of scan `scan` (< size(); each slot once, asserted).
  void put(std::size_t scan, SampleCloud cloud);

  // Whether scan `scan`'s cloud was put.
  bool has(std::size_t scan) const {
    assert(scan < slots_.size() && "a slot of the shelf");
    return slots_[scan].put;
  }

  // The cloud of scan `scan` (put before, asserted). Throws
  // core::RuntimeFailure when the file cannot be read back.
  std::shared_ptr<const SampleCloud> get(std::size_t scan);

  // Its number of samples, without reading it back.
  std::size_t count(std::size_t scan) const {
    assert(scan < slots_.size() && "a slot of the shelf");
    return slots_[scan].count;
  }

 private:
  struct Slot {
    bool put = false;
    std::size_t count = 0;
    std::vector<core::SpillFile::Extent> extents;  // points, normals, pixels; none: pinned
    std::shared_ptr<const SampleCloud> in_memory;
  };
  void keep(std::size_t scan);

  std::vector<Slot> slots_;
  std::size_t kept_;
  std::list<std::size_t> recent_;  // parked slots in memory, the last used first
  core::SpillFile spill_;
};

}  // namespace scanbench::registration

// Where the level-of-detail build keeps points between its passes, in
// numbered slots (one a chunk): in memory when the model fits the build's
// memory, else in a temporary file (core::SpillFile), so the build's memory
// stays that of the chunks it works on. Safe from several threads.
#pragma once

#include <cstddef>
#include <mutex>
#include <span>
#include <vector>

#include "core/spill_file.hpp"
#include "modeling/lod/octree_sampling.hpp"

namespace scanbench::lod {

class ParkedPoints {
 public:
  ParkedPoints(std::size_t slots, bool in_memory);

  // Room for `points` points in slot `slot`, mapped at once (in memory
  // only: a growing slot would copy itself and fault page after page).
  void reserve(std::size_t slot, std::size_t points);

  // Appends `points` to slot `slot`. Throws core::RuntimeFailure naming the
  // temporary folder when the file cannot take them (a full disk).
  void add(std::size_t slot, std::span<const BuildPoint> points);

  // Every point of slot `slot`, which is empty afterwards (its disk space
  // given back).
  std::vector<BuildPoint> take(std::size_t slot);

 private:
  std::mutex mutex_;
  bool in_memory_;
  std::vector<std::vector<BuildPoint>> memory_;
  core::SpillFile file_;
  std::vector<std::vector<core::SpillFile::Extent>> extents_;
};

}  // namespace scanbench::lod

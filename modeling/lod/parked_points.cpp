#include "modeling/lod/parked_points.hpp"

#include "core/errors.hpp"
#include "core/memory.hpp"

namespace scanbench::lod {

ParkedPoints::ParkedPoints(std::size_t slots, bool in_memory)
    : in_memory_(in_memory), memory_(in_memory ? slots : 0), extents_(in_memory ? 0 : slots) {}

void ParkedPoints::reserve(std::size_t slot, std::size_t points) {
  const std::lock_guard lock(mutex_);
  if (in_memory_) core::reserve_mapped(memory_[slot], points);
}

void ParkedPoints::add(std::size_t slot, std::span<const BuildPoint> points) {
  if (points.empty()) return;
  const std::lock_guard lock(mutex_);
  if (in_memory_) {
    memory_[slot].insert(memory_[slot].end(), points.begin(), points.end());
    return;
  }
  const auto extent = file_.put(points.data(), points.size_bytes());
  if (!extent) {
    core::FilePosition position;
    position.detail = "parking points for the level-of-detail store";
    throw core::RuntimeFailure(file_.folder().string(), position,
                               "the temporary folder has no room left (TMPDIR)");
  }
  extents_[slot].push_back(*extent);
}

std::vector<BuildPoint> ParkedPoints::take(std::size_t slot) {
  std::vector<core::SpillFile::Extent> extents;
  {
    const std::lock_guard lock(mutex_);
    if (in_memory_) return std::exchange(memory_[slot], {});
    extents = std::exchange(extents_[slot], {});
  }
  std::uint64_t bytes = 0;
  for (const auto& e : extents) bytes += e.bytes;
  std::vector<BuildPoint> points;
  core::reserve_mapped(points, bytes / sizeof(BuildPoint));
  points.resize(bytes / sizeof(BuildPoint));
  auto* at = reinterpret_cast<std::uint8_t*>(points.data());
  for (const auto& e : extents) {
    file_.get(e, at);  // reads at an offset: no turn to take
    at += e.bytes;
  }
  const std::lock_guard lock(mutex_);
  for (const auto& e : extents) file_.release(e);
  return points;
}

}  // namespace scanbench::lod

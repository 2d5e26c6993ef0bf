#include "registration/sample_shelf.hpp"

#include <algorithm>
#include <cassert>
#include <utility>

namespace scanbench::registration {

SampleShelf::SampleShelf(std::size_t scans, std::size_t kept) : slots_(scans), kept_(kept) {}

void SampleShelf::put(std::size_t scan, SampleCloud cloud) {
  assert(scan < slots_.size() && !slots_[scan].put && "each slot is put once");
  Slot& slot = slots_[scan];
  slot.put = true;
  slot.count = cloud.size();
  if (auto extents = spill_.put_vectors(cloud.points, cloud.normals, cloud.pixels))
    slot.extents = std::move(*extents);
  slot.in_memory = std::make_shared<const SampleCloud>(std::move(cloud));
  if (!slot.extents.empty()) keep(scan);
}

std::shared_ptr<const SampleCloud> SampleShelf::get(std::size_t scan) {
  assert(scan < slots_.size() && slots_[scan].put && "the cloud was put");
  Slot& slot = slots_[scan];
  if (slot.in_memory == nullptr) {
    auto cloud = std::make_shared<SampleCloud>();
    spill_.get_vectors(slot.extents, cloud->points, cloud->normals, cloud->pixels);
    slot.in_memory = std::move(cloud);
  }
  std::shared_ptr<const SampleCloud> out = slot.in_memory;
  if (!slot.extents.empty()) keep(scan);  // may let it go from the shelf, not from `out`
  return out;
}

// Marks parked slot `scan` as used last, and lets the least recently used
// beyond `kept_` go from memory (their clouds stay in the file, and in the
// hands of whoever still holds them).
void SampleShelf::keep(std::size_t scan) {
  const auto at = std::find(recent_.begin(), recent_.end(), scan);
  if (at != recent_.end()) recent_.erase(at);
  recent_.push_front(scan);
  while (recent_.size() > kept_) {
    slots_[recent_.back()].in_memory.reset();
    recent_.pop_back();
  }
}

}  // namespace scanbench::registration

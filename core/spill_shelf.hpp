// Values of one type in numbered slots (one a scan, say), parked in a
// temporary file (SpillFile) as they are put and read back when asked for,
// with the `kept` used last also in memory. So a stage holds the values it
// works on, not every value that waits. Where the file cannot take a value
// (none could be made, or the disk is full), that value stays in memory;
// bytes_in_memory() counts those, for the stage's memory limit.
//
// T names the vectors that hold it, as std::tie of them, through
// `vectors()` (const and not), and has size(). Not thread-safe: one
// stage's thread puts and gets.
#pragma once

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include "core/spill_file.hpp"

namespace scanbench::core {

template <typename T>
class SpillShelf {
 public:
  // `slots` empty slots; besides the values handed out and still held, at
  // most `kept` stay in memory (the ones used last; 0: none).
  SpillShelf(std::size_t slots, std::size_t kept) : slots_(slots), kept_(kept) {}

  std::size_t size() const { return slots_.size(); }

  // Puts the value of slot `slot` (< size(); each slot once, asserted).
  void put(std::size_t slot, T value) {
    assert(slot < slots_.size() && !slots_[slot].put && "each slot is put once");
    fill(slot, std::move(value));
  }

  // Puts `value` in a new slot at the end, and returns that slot.
  std::size_t add(T value) {
    slots_.emplace_back();
    fill(slots_.size() - 1, std::move(value));
    return slots_.size() - 1;
  }

  // Whether slot `slot` holds a value (put and not released).
  bool has(std::size_t slot) const {
    assert(slot < slots_.size() && "a slot of the shelf");
    return slots_[slot].put && !slots_[slot].released;
  }

  // The value of slot `slot` (has(slot), asserted). Throws
  // core::RuntimeFailure when the file cannot be read back.
  std::shared_ptr<const T> get(std::size_t slot) {
    assert(has(slot) && "the value was put and not released");
    Slot& s = slots_[slot];
    if (s.in_memory == nullptr) {
      auto value = std::make_shared<T>();
      std::apply([&](auto&... v) { spill_.get_vectors(s.extents, v...); }, value->vectors());
      s.in_memory = std::move(value);
    }
    std::shared_ptr<const T> out = s.in_memory;
    if (!s.extents.empty()) keep(slot);  // may let it go from the shelf, not from `out`
    return out;
  }

  // The size() of slot `slot`'s value, without reading it back.
  std::size_t count(std::size_t slot) const {
    assert(has(slot) && "the value was put and not released");
    return slots_[slot].count;
  }

  // Lets slot `slot`'s value go, from memory and from the file: it will not
  // be asked for again. Nothing where the slot holds no value.
  void release(std::size_t slot) {
    if (!has(slot)) return;
    Slot& s = slots_[slot];
    s.released = true;
    for (const SpillFile::Extent& extent : s.extents) spill_.release(extent);
    s.extents.clear();
    s.in_memory.reset();
    pinned_bytes_ -= s.pinned_bytes;
    s.pinned_bytes = 0;
    recent_.remove(slot);
  }

  // The bytes of the values that the file could not take.
  std::uint64_t bytes_in_memory() const { return pinned_bytes_; }

 private:
  struct Slot {
    bool put = false;
    bool released = false;
    std::size_t count = 0;
    std::vector<SpillFile::Extent> extents;  // one a vector of T; none: pinned in memory
    std::uint64_t pinned_bytes = 0;
    std::shared_ptr<const T> in_memory;
  };

  // Parks `value` in empty slot `slot`, or pins it in memory where the file
  // cannot take it.
  void fill(std::size_t slot, T value) {
    Slot& s = slots_[slot];
    s.put = true;
    s.count = value.size();
    if (auto extents = std::apply([this](const auto&... v) { return spill_.put_vectors(v...); },
                                  value.vectors())) {
      s.extents = std::move(*extents);
    } else {
      s.pinned_bytes = bytes_of(value);
      pinned_bytes_ += s.pinned_bytes;
    }
    s.in_memory = std::make_shared<const T>(std::move(value));
    if (!s.extents.empty()) keep(slot);
  }

  static std::uint64_t bytes_of(const T& value) {
    return std::apply([](const auto&... v) { return ((v.size() * sizeof(v[0])) + ... + 0); },
                      value.vectors());
  }

  // Marks parked slot `slot` as used last, and lets the least recently used
  // beyond `kept_` go from memory (their values stay in the file, and in the
  // hands of whoever still holds them).
  void keep(std::size_t slot) {
    const auto at = std::find(recent_.begin(), recent_.end(), slot);
    if (at != recent_.end()) recent_.erase(at);
    recent_.push_front(slot);
    while (recent_.size() > kept_) {
      slots_[recent_.back()].in_memory.reset();
      recent_.pop_back();
    }
  }

  std::vector<Slot> slots_;
  std::size_t kept_;
  std::list<std::size_t> recent_;  // parked slots in memory, the last used first
  std::uint64_t pinned_bytes_ = 0;
  SpillFile spill_;
};

}  // namespace scanbench::core

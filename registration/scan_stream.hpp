// Where a stage that works on many scans gets them: one at a time, by
// position in the scan list, in an order it announces first. A stream over
// a project loads each scan when it is asked for and lets it go when the
// announced order no longer needs it, so a campaign larger than memory can
// be registered or merged; a stream over scans in memory just hands them
// out.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "registration/prepared_scan.hpp"

namespace scanbench::registration {

class ScanStream {
 public:
  virtual ~ScanStream() = default;

  virtual std::size_t size() const = 0;

  // The positions the following get() calls will ask for, in their order
  // (a position may repeat). Replaces the previous plan.
  virtual void plan(std::vector<int> order) = 0;

  // Scan `k`, the next position of the plan (asserted), held as long as
  // the pointer lives. A stream over a project may throw what loading
  // throws (core::InputError, core::MemoryShortage, core::Cancelled).
  virtual std::shared_ptr<const PreparedScan> get(int k) = 0;
};

// Scans already in memory, which must outlive the stream; plans are not
// checked.
class ScansInMemory final : public ScanStream {
 public:
  explicit ScansInMemory(std::span<const PreparedScan> scans) : scans_(scans) {}
  std::size_t size() const override { return scans_.size(); }
  void plan(std::vector<int>) override {}
  std::shared_ptr<const PreparedScan> get(int k) override {
    // Not owned: an empty control block, the pointer only.
    return {std::shared_ptr<const PreparedScan>(), &scans_[static_cast<std::size_t>(k)]};
  }

 private:
  std::span<const PreparedScan> scans_;
};

}  // namespace scanbench::registration

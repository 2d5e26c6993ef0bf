// Progress and cancellation, one interface for every stage: the CLI draws a
// progress bar from it, the workbench a progress dialog with a Cancel button.
//
// A stage calls update() between units of work (a scan, a pair) and
// throw_if_cancelled() where stopping is safe: before it writes anything. A
// cancelled stage throws core::Cancelled and leaves the project unchanged.
#pragma once

#include <atomic>
#include <cstddef>
#include <string>
#include <string_view>

namespace scanbench::core {

struct ProgressStep {
  std::string_view stage;  // "import", "geometry", "register", "merge", …
  std::size_t done = 0;    // units finished so far
  std::size_t total = 0;   // units in all; 0 when unknown
  std::string_view note;   // what was just finished, for people ("scan north")
};

class Progress {
 public:
  Progress() = default;
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  virtual ~Progress() = default;

  // Called on the stage's own thread. The base class ignores it, so a plain
  // Progress is "report nothing, never cancel".
  virtual void update(const ProgressStep& step) { static_cast<void>(step); }

  // Safe from any thread, e.g. a GUI's Cancel button while the stage runs.
  void request_cancel() { cancel_.store(true, std::memory_order_relaxed); }
  bool cancel_requested() const { return cancel_.load(std::memory_order_relaxed); }

  // Throws Cancelled naming `stage` once cancellation was requested.
  void throw_if_cancelled(std::string_view stage) const;

 private:
  std::atomic<bool> cancel_{false};
};

}  // namespace scanbench::core

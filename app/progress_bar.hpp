// The CLI's view of core::Progress: a one-line progress bar on stderr, drawn
// only when stderr is a terminal so that logs and pipes stay clean.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "core/progress.hpp"

namespace scanbench::app {

class ProgressBar : public core::Progress {
 public:
  ProgressBar();
  ~ProgressBar() override;  // ends the line when anything was drawn

  // Redraws as "stage [#####.....] done/total note, about 2 min 10 s left";
  // total 0 draws no bar. The time left assumes the units still to come
  // take as long as those done since the stage's first update.
  void update(const core::ProgressStep& step) override;

 private:
  bool enabled_ = false;
  bool drawn_ = false;
  std::string stage_;  // the stage being timed
  std::size_t last_done_ = 0;
  std::size_t done_at_start_ = 0;  // units done when the timing began
  std::chrono::steady_clock::time_point started_;
};

// "about 45 s left", "about 3 min 05 s left", "about 1 h 02 min left";
// empty below a second.
std::string time_left_text(double seconds);

}  // namespace scanbench::app

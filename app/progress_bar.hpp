// The CLI's view of core::Progress: a one-line progress bar on stderr, drawn
// only when stderr is a terminal so that logs and pipes stay clean.
#pragma once

#include <string>

#include "core/progress.hpp"

namespace scanbench::app {

class ProgressBar : public core::Progress {
 public:
  ProgressBar();
  ~ProgressBar() override;  // ends the line when anything was drawn

  // Redraws as "stage [#####.....] done/total note"; total 0 draws no bar.
  void update(const core::ProgressStep& step) override;

 private:
  bool enabled_ = false;
  bool drawn_ = false;
};

}  // namespace scanbench::app

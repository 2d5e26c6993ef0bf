// A one-line progress bar on stderr, drawn only when stderr is a terminal so
// that logs and pipes stay clean.
#pragma once

#include <cstddef>
#include <string>

namespace scanbench::app {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();  // ends the line when anything was drawn
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Redraws as "label [#####.....] done/total note"; total 0 draws no bar.
  void update(std::size_t done, std::size_t total, const std::string& note = {});

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
};

}  // namespace scanbench::app

#include "app/progress_bar.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace scanbench::app {

ProgressBar::ProgressBar() : enabled_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  if (drawn_) fmt::print(stderr, "\n");
}

void ProgressBar::update(const core::ProgressStep& step) {
  if (!enabled_) return;
  constexpr std::size_t kWidth = 30;
  std::string bar;
  if (step.total > 0) {
    const std::size_t filled = std::min(kWidth, step.done * kWidth / step.total);
    bar = fmt::format("[{}{}] {}/{}", std::string(filled, '#'), std::string(kWidth - filled, '.'),
                      step.done, step.total);
  }
  fmt::print(stderr, "\r\033[K{} {} {}", step.stage, bar, step.note);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace scanbench::app

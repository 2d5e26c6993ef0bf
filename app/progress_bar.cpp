#include "app/progress_bar.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace scanbench::app {

std::string time_left_text(double seconds) {
  if (!(seconds >= 1.0)) return "";
  const auto whole = static_cast<long long>(std::lround(seconds));
  if (whole < 60) return fmt::format("about {} s left", whole);
  if (whole < 3600) return fmt::format("about {} min {:02} s left", whole / 60, whole % 60);
  return fmt::format("about {} h {:02} min left", whole / 3600, (whole % 3600) / 60);
}

ProgressBar::ProgressBar() : enabled_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  if (drawn_) fmt::print(stderr, "\n");
}

void ProgressBar::update(const core::ProgressStep& step) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (step.stage != stage_ || step.done < last_done_ || stage_.empty()) {
    stage_ = std::string(step.stage);
    started_ = now;
    done_at_start_ = step.done;
  }
  last_done_ = step.done;
  constexpr std::size_t kWidth = 30;
  std::string bar;
  std::string left;
  if (step.total > 0) {
    const std::size_t filled = std::min(kWidth, step.done * kWidth / step.total);
    bar = fmt::format("[{}{}] {}/{}", std::string(filled, '#'), std::string(kWidth - filled, '.'),
                      step.done, step.total);
    // The units done since the timing began, at the pace they took.
    if (step.done > done_at_start_ && step.done < step.total) {
      const double elapsed = std::chrono::duration<double>(now - started_).count();
      left = time_left_text(elapsed * static_cast<double>(step.total - step.done) /
                            static_cast<double>(step.done - done_at_start_));
    }
  }
  fmt::print(stderr, "\r\033[K{} {} {}{}{}", step.stage, bar, step.note, left.empty() ? "" : ", ",
             left);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace scanbench::app

#include "app/progress_bar.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>

namespace scanbench::app {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
  if (drawn_) fmt::print(stderr, "\n");
}

void ProgressBar::update(std::size_t done, std::size_t total, const std::string& note) {
  if (!enabled_) return;
  constexpr std::size_t kWidth = 30;
  std::string bar;
  if (total > 0) {
    const std::size_t filled = std::min(kWidth, done * kWidth / total);
    bar = fmt::format("[{}{}] {}/{}", std::string(filled, '#'), std::string(kWidth - filled, '.'),
                      done, total);
  }
  fmt::print(stderr, "\r\033[K{} {} {}", label_, bar, note);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace scanbench::app

#include "app/workbench/background_command.hpp"

#include <utility>

namespace scanbench::app::workbench {

BackgroundCommand::~BackgroundCommand() {
  if (future_.valid()) future_.wait();
}

bool BackgroundCommand::ask(std::string label, std::function<void()> work) {
  if (asked() || running()) return false;
  label_ = std::move(label);
  work_ = std::move(work);
  return true;
}

void BackgroundCommand::start() {
  if (!asked() || running()) return;
  started_ = std::chrono::steady_clock::now();
  future_ = std::async(std::launch::async, [this, work = std::exchange(work_, {})] {
    // Timed here: the window's thread sees the end up to a frame later.
    struct Timer {
      BackgroundCommand& command;
      ~Timer() {
        command.took_ =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - command.started_)
                .count();
      }
    } timer{*this};
    work();
  });
}

bool BackgroundCommand::collect(std::chrono::milliseconds within) {
  if (!future_.valid()) return true;
  if (future_.wait_for(within) != std::future_status::ready) return false;
  std::future<void> ended = std::move(future_);
  ended.get();  // rethrows
  return true;
}

void BackgroundCommand::wait() {
  if (future_.valid()) future_.wait();
}

double BackgroundCommand::seconds() const {
  if (!future_.valid()) return took_;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

}  // namespace scanbench::app::workbench

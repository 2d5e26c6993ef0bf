#include "app/workbench/background_command.hpp"

#include <utility>

namespace scanbench::app::workbench {

BackgroundCommand::~BackgroundCommand() {
  if (future_.valid()) future_.wait();  // what it threw is lost with the window
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
  frames_while_running = 0;
  future_ = std::async(std::launch::async, std::exchange(work_, {}));
}

bool BackgroundCommand::finished() {
  if (!future_.valid()) return true;
  if (future_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return false;
  took_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  std::future<void> done = std::move(future_);
  done.get();  // rethrows
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

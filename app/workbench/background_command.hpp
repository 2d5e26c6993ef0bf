// A command the workbench runs on a worker thread while its window goes on
// repainting: a panel asks for it during a frame, it starts once that frame
// is drawn (BackgroundCommand::start), and the window shows that last frame
// with a progress indicator until it ends. One runs at a time.
//
// The work may touch the session and the workbench's state; while it runs,
// the window's thread touches neither (workbench.cpp draws the frozen frame,
// input.hpp takes only moves and releases, which change neither). The end
// of the work is the one synchronisation point: whatever it wrote is seen
// by the frames after it. No OpenGL or ImGui call belongs in the work.
#pragma once

#include <chrono>
#include <functional>
#include <future>
#include <string>

namespace scanbench::app::workbench {

class BackgroundCommand {
 public:
  BackgroundCommand() = default;
  ~BackgroundCommand();  // waits for a running command (what it threw is dropped)
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;

  // Asks for `work`, shown as `label` ("Committing \"wall\""). False, and
  // nothing asked, when a command is asked for or running already.
  bool ask(std::string label, std::function<void()> work);
  // A command is asked for and not started yet.
  bool asked() const { return static_cast<bool>(work_); }
  // A command has started and its end has not been collected.
  bool running() const { return future_.valid(); }

  // Starts the command asked for on a worker thread; nothing when none is.
  void start();
  // Waits up to `within` for the running command to end. Once it has, the
  // runner is idle, seconds() is how long the work took, and true is
  // returned, or what the work threw is rethrown (once). True when none runs.
  bool collect(std::chrono::milliseconds within = std::chrono::milliseconds(0));
  // Blocks until the running command ends; collect() then returns at once.
  void wait();

  const std::string& label() const { return label_; }
  // Since the command started, or how long the last one's work took.
  double seconds() const;

 private:
  std::string label_;
  std::function<void()> work_;
  std::future<void> future_;
  std::chrono::steady_clock::time_point started_;
  double took_ = 0.0;  // written by the worker before its end
};

}  // namespace scanbench::app::workbench

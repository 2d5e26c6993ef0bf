// A command the workbench runs on a worker thread while its window goes on
// repainting: a panel asks for it during a frame, it starts once that frame
// is drawn (BackgroundCommand::start), and the window shows that last frame
// with a progress indicator until it ends. One runs at a time.
//
// The work may touch the session and the workbench's state; while it runs,
// the window's thread touches neither (workbench.cpp draws the frozen frame,
// input.hpp takes only moves and releases). The end of the work is the one
// synchronisation point: whatever it wrote is seen by the frames after it.
// No OpenGL or ImGui call belongs in the work.
#pragma once

#include <chrono>
#include <exception>
#include <functional>
#include <future>
#include <string>

namespace scanbench::app::workbench {

class BackgroundCommand {
 public:
  BackgroundCommand() = default;
  ~BackgroundCommand();  // waits for a running command
  BackgroundCommand(const BackgroundCommand&) = delete;
  BackgroundCommand& operator=(const BackgroundCommand&) = delete;

  // Asks for `work`, shown as `label` ("Committing \"wall\""). False when a
  // command is asked for or running already: one at a time.
  bool ask(std::string label, std::function<void()> work);
  bool asked() const { return static_cast<bool>(work_); }
  bool running() const { return future_.valid(); }

  // Starts the command asked for on a worker thread.
  void start();
  // Whether the running command has ended; once it has, the runner is idle
  // and seconds() is its duration. Rethrows what the work threw.
  bool finished();
  // Blocks until the running command ends (finished() then returns true).
  void wait();

  const std::string& label() const { return label_; }
  // Since the command started, or how long the last one took.
  double seconds() const;
  // Frames drawn while the command ran: the window kept repainting.
  long frames_while_running = 0;

 private:
  std::string label_;
  std::function<void()> work_;
  std::future<void> future_;
  std::chrono::steady_clock::time_point started_;
  double took_ = 0.0;
};

}  // namespace scanbench::app::workbench

// The workbench's background command (app/workbench/background_command):
// the work runs on another thread while the caller goes on drawing frames,
// its end is seen once, and what it threw reaches the window's thread.
#include <gtest/gtest.h>

#include <future>
#include <stdexcept>
#include <thread>

#include "app/workbench/background_command.hpp"

namespace scanbench {
namespace {

using app::workbench::BackgroundCommand;

TEST(BackgroundCommand, RunsOnAnotherThreadWhileTheCallerGoesOn) {
  BackgroundCommand command;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::thread::id ran_on;
  int result = 0;
  ASSERT_TRUE(command.ask("Committing", [&] {
    ran_on = std::this_thread::get_id();
    released.wait();
    result = 42;
  }));
  EXPECT_TRUE(command.asked());
  EXPECT_FALSE(command.running());
  command.start();
  EXPECT_FALSE(command.asked());
  EXPECT_TRUE(command.running());
  // The caller's frames go on while the work waits; a second command is
  // refused meanwhile.
  for (int frame = 0; frame < 5; ++frame) EXPECT_FALSE(command.finished());
  EXPECT_FALSE(command.ask("Grouping", [] {}));
  EXPECT_EQ(command.label(), "Committing");
  release.set_value();
  command.wait();
  EXPECT_TRUE(command.finished());
  EXPECT_FALSE(command.running());
  EXPECT_EQ(result, 42);  // seen once finished
  EXPECT_NE(ran_on, std::this_thread::get_id());
  EXPECT_GE(command.seconds(), 0.0);
  // Idle again: the next command may be asked for.
  EXPECT_TRUE(command.ask("Grouping", [] {}));
}

TEST(BackgroundCommand, OneIsAskedForAtATime) {
  BackgroundCommand command;
  int ran = 0;
  ASSERT_TRUE(command.ask("first", [&] { ran += 1; }));
  EXPECT_FALSE(command.ask("second", [&] { ran += 10; }));
  command.start();
  command.wait();
  EXPECT_TRUE(command.finished());
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(command.label(), "first");
}

TEST(BackgroundCommand, WhatTheWorkThrewReachesTheCaller) {
  BackgroundCommand command;
  ASSERT_TRUE(command.ask("Failing", [] { throw std::runtime_error("disk full"); }));
  command.start();
  command.wait();
  EXPECT_THROW(command.finished(), std::runtime_error);
  EXPECT_FALSE(command.running());
  EXPECT_TRUE(command.finished());  // thrown once; idle after
}

}  // namespace
}  // namespace scanbench

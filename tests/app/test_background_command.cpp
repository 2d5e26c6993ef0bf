// The workbench's background command (app/workbench/background_command):
// the work runs on another thread while the caller goes on drawing frames,
// its end is seen once, and what it threw reaches the window's thread.
#include <gtest/gtest.h>

#include <chrono>
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
  // The caller's frames go on while the work waits (a work run on the
  // caller's thread would never have returned from start()); a second
  // command is refused meanwhile.
  for (int frame = 0; frame < 5; ++frame)
    EXPECT_FALSE(command.collect(std::chrono::milliseconds(10)));
  EXPECT_FALSE(command.ask("Grouping", [] {}));
  EXPECT_EQ(command.label(), "Committing");
  EXPECT_GE(command.seconds(), 0.04);  // the five frames' waits, at least
  release.set_value();
  EXPECT_TRUE(command.collect(std::chrono::seconds(60)));
  EXPECT_FALSE(command.running());
  EXPECT_EQ(result, 42);  // seen once collected
  EXPECT_NE(ran_on, std::this_thread::get_id());
  EXPECT_GE(command.seconds(), 0.04);  // how long the work took
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
  EXPECT_TRUE(command.collect());
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(command.label(), "first");
}

TEST(BackgroundCommand, WhatTheWorkThrewReachesTheCaller) {
  BackgroundCommand command;
  ASSERT_TRUE(command.ask("Failing", [] { throw std::runtime_error("disk full"); }));
  command.start();
  command.wait();
  EXPECT_THROW(command.collect(), std::runtime_error);
  EXPECT_FALSE(command.running());
  EXPECT_TRUE(command.collect());  // thrown once; idle after
}

TEST(BackgroundCommand, StartWithNothingAskedForDoesNothingAndTheEndIsAwaited) {
  int ran = 0;
  {
    BackgroundCommand command;
    command.start();
    EXPECT_FALSE(command.running());
    ASSERT_TRUE(command.ask("slow", [&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      ran = 1;
    }));
    command.start();
  }  // destroyed while it runs: waits for it
  EXPECT_EQ(ran, 1);
}

}  // namespace
}  // namespace scanbench

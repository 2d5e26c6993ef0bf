// core::ProcessIdentity tells a running process from a gone one, and from
// another process that got the same pid.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/process.hpp"

namespace scanbench::core {
namespace {

TEST(Process, ThisProcessIsRunningAndNamesItsMachine) {
  const ProcessIdentity self = this_process();
  EXPECT_EQ(self.pid, ::getpid());
  EXPECT_GT(self.start_ticks, 0);
  EXPECT_NE(self.machine.find(" boot "), std::string::npos) << self.machine;
  EXPECT_NE(self.machine.find("pid:["), std::string::npos) << self.machine;
  EXPECT_EQ(this_process().machine, self.machine);
  EXPECT_TRUE(is_running(self));
}

TEST(Process, AGoneProcessAndAReusedPidAreNotRunning) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  EXPECT_FALSE(is_running({this_process().machine, child, 1}));
  ProcessIdentity reused = this_process();
  reused.start_ticks += 1;  // the same pid, started at another time
  EXPECT_FALSE(is_running(reused));
}

}  // namespace
}  // namespace scanbench::core

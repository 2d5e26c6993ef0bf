// Which process this is, in a form that stays meaningful in a shared file:
// a project's pending command names the process writing it, and another
// process must tell for sure whether that writer is gone before it cleans
// up after it. A pid alone cannot: it is reused, and it means another
// process on another machine, after a reboot, or in another container.
#pragma once

#include <cstdint>
#include <string>

namespace scanbench::core {

struct ProcessIdentity {
  // The host name, the kernel's boot id and the pid namespace: where `pid`
  // means this process. Equal machines can judge each other's processes.
  std::string machine;
  std::int64_t pid = 0;
  // When the process started, in clock ticks after boot (/proc/PID/stat):
  // a reused pid has another.
  std::int64_t start_ticks = 0;
};

ProcessIdentity this_process();

// Whether `process` still runs. Only meaningful when its machine equals
// this_process().machine; callers leave other machines' processes alone.
bool is_running(const ProcessIdentity& process);

}  // namespace scanbench::core

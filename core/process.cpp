#include "core/process.hpp"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

namespace scanbench::core {
namespace {

std::string first_line(const char* file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

// Field 22 of /proc/PID/stat, the start time; none when there is no such
// process (or no /proc). The command name (field 2) is in parentheses and
// may hold blanks and parentheses itself, so counting starts after its last
// ')'.
std::optional<std::int64_t> start_ticks(std::int64_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return std::nullopt;
  const std::size_t name_end = stat.rfind(')');
  if (name_end == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(name_end + 1));
  std::string field;
  for (int k = 3; k < 22 && fields >> field; ++k) {
  }
  std::int64_t ticks = 0;
  if (fields >> ticks) return ticks;
  return std::nullopt;
}

}  // namespace

ProcessIdentity this_process() {
  ProcessIdentity self;
  std::array<char, 256> host{};
  if (::gethostname(host.data(), host.size() - 1) == 0) self.machine = host.data();
  // Appended piece by piece: GCC 12 warns falsely on `" x " + std::string`.
  self.machine.append(" boot ").append(first_line("/proc/sys/kernel/random/boot_id"));
  std::error_code error;
  self.machine.append(" ").append(
      std::filesystem::read_symlink("/proc/self/ns/pid", error).string());
  self.pid = ::getpid();
  self.start_ticks = start_ticks(self.pid).value_or(0);
  return self;
}

bool is_running(const ProcessIdentity& process) {
  if (process.pid <= 0) return false;
  if (const std::optional<std::int64_t> ticks = start_ticks(process.pid))
    return *ticks == process.start_ticks;
  // No /proc entry: gone, unless /proc itself is not there to tell.
  if (std::filesystem::exists("/proc/self/stat")) return false;
  return ::kill(static_cast<pid_t>(process.pid), 0) == 0 || errno != ESRCH;
}

}  // namespace scanbench::core

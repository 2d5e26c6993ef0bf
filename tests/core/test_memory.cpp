// core::available_memory_bytes takes the least of what the system, the
// memory cgroups and RLIMIT_AS allow; core::check_memory refuses beyond it.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <optional>
#include <string>

#include "core/errors.hpp"
#include "core/memory.hpp"

namespace scanbench::core {
namespace {

std::uint64_t vm_size_bytes() {
  std::ifstream status("/proc/self/status");
  std::string key;
  std::uint64_t kilobytes = 0;
  while (status >> key) {
    if (key == "VmSize:" && status >> kilobytes) return kilobytes * 1024;
  }
  return 0;
}

TEST(Memory, TheSystemsAvailableMemoryIsKnownOnLinux) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  ASSERT_TRUE(available.has_value());
  EXPECT_GT(*available, 0u);
  EXPECT_NO_THROW(check_memory(1024, "small.ptx"));
}

// In a child: with the address space limited to 256 MB beyond what is
// mapped, that is what is available, and 1 GB is refused.
TEST(Memory, AnAddressSpaceLimitBoundsWhatIsAvailable) {
  const pid_t child = ::fork();
  if (child == 0) {
    const std::uint64_t headroom = std::uint64_t{256} << 20;
    const rlimit limit{vm_size_bytes() + headroom, RLIM_INFINITY};
    if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(3);
    const std::optional<std::uint64_t> available = available_memory_bytes();
    if (!available || *available > headroom) ::_exit(4);
    try {
      check_memory(std::uint64_t{1} << 30, "big.ptx");
      ::_exit(5);
    } catch (const MemoryShortage& e) {
      ::_exit(std::string(e.what()).find("big.ptx") != std::string::npos ? 0 : 6);
    }
  }
  ASSERT_GT(child, 0);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: setrlimit failed, 4: limit not seen, 5: not refused, "
                                       "6: message without the file";
}

}  // namespace
}  // namespace scanbench::core

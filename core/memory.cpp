#include "core/memory.hpp"

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/errors.hpp"

namespace scanbench::core {
namespace {

namespace fs = std::filesystem;

void keep_least(std::optional<std::uint64_t>& least, std::uint64_t value) {
  least = least ? std::min(*least, value) : value;
}

// The number a one-value file holds; none for "max" (no limit) or no file.
std::optional<std::uint64_t> read_number(const fs::path& file) {
  std::ifstream in(file);
  std::uint64_t value = 0;
  if (in >> value) return value;
  return std::nullopt;
}

// The value of `key` in a "key value" per line file (/proc/meminfo,
// memory.stat, /proc/self/status); none when absent.
std::optional<std::uint64_t> keyed_number(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string name;
    std::uint64_t value = 0;
    if (fields >> name >> value && name == key) return value;
  }
  return std::nullopt;
}

// What one cgroup folder still allows, or none when it sets no limit.
std::optional<std::uint64_t> cgroup_headroom(const fs::path& folder, bool v2) {
  const std::optional<std::uint64_t> limit =
      read_number(folder / (v2 ? "memory.max" : "memory.limit_in_bytes"));
  const std::optional<std::uint64_t> usage =
      read_number(folder / (v2 ? "memory.current" : "memory.usage_in_bytes"));
  if (!limit || !usage || *limit >= (std::uint64_t{1} << 62)) return std::nullopt;  // no limit
  const std::uint64_t cache =
      keyed_number(folder / "memory.stat", v2 ? "inactive_file" : "total_inactive_file")
          .value_or(0);
  const std::uint64_t used = *usage > cache ? *usage - cache : 0;
  return *limit > used ? *limit - used : 0;
}

// The least headroom over the memory cgroups of this process and their
// ancestors, from /proc/self/cgroup ("id:controllers:path" lines; the v2
// line has no controllers).
std::optional<std::uint64_t> cgroups_headroom() {
  std::optional<std::uint64_t> least;
  std::ifstream cgroups("/proc/self/cgroup");
  std::string line;
  while (std::getline(cgroups, line)) {
    const std::size_t first = line.find(':');
    const std::size_t second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const bool v2 = second == first + 1;
    bool memory = false;
    std::istringstream controllers(line.substr(first + 1, second - first - 1));
    for (std::string name; std::getline(controllers, name, ',');)
      memory = memory || name == "memory";
    if (!v2 && !memory) continue;
    const fs::path root = v2 ? "/sys/fs/cgroup" : "/sys/fs/cgroup/memory";
    for (fs::path group = line.substr(second + 1);; group = group.parent_path()) {
      if (const auto headroom = cgroup_headroom(root / group.relative_path(), v2))
        keep_least(least, *headroom);
      if (group.empty() || group == group.parent_path()) break;
    }
  }
  return least;
}

// What RLIMIT_AS leaves of the address space, or none without a limit.
std::optional<std::uint64_t> address_space_headroom() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
  const std::uint64_t used = keyed_number("/proc/self/status", "VmSize:").value_or(0) * 1024;
  return limit.rlim_cur > used ? limit.rlim_cur - used : 0;
}

}  // namespace

std::string gigabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) / 1e9);
  return text;
}

std::optional<std::uint64_t> available_memory_bytes() {
  std::optional<std::uint64_t> least;
  if (const auto system = keyed_number("/proc/meminfo", "MemAvailable:"))
    keep_least(least, *system * 1024);  // reported in kB
  if (const auto cgroups = cgroups_headroom()) keep_least(least, *cgroups);
  if (const auto address_space = address_space_headroom()) keep_least(least, *address_space);
  return least;
}

std::optional<std::uint64_t> peak_resident_bytes() {
  const std::optional<std::uint64_t> kilobytes = keyed_number("/proc/self/status", "VmHWM:");
  if (!kilobytes) return std::nullopt;
  return *kilobytes * 1024;
}

void check_memory(std::uint64_t bytes, const std::string& file) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (available && bytes > *available) {
    throw MemoryShortage(file, {},
                         "reading it needs " + gigabytes(bytes) + " of memory, " +
                             gigabytes(*available) + " are available");
  }
}

void check_memory_limit(std::uint64_t bytes, std::uint64_t limit, const std::string& file,
                        const std::string& stage, const std::string& what) {
  if (bytes <= limit) return;
  throw MemoryShortage(file, {},
                       stage + " needs about " + gigabytes(bytes) + " for " + what +
                           ", more than its memory limit of " + gigabytes(limit) +
                           " (--memory-limit)");
}

void map_now(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
  constexpr std::size_t kWorthIt = std::size_t{1} << 20;  // below, a few faults
  if (data == nullptr || bytes < kWorthIt) return;
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto begin = reinterpret_cast<std::uintptr_t>(data) & ~(page - 1);
  const auto end = reinterpret_cast<std::uintptr_t>(data) + bytes;
  void* const region = reinterpret_cast<void*>(begin);
  madvise(region, end - begin, MADV_HUGEPAGE);  // fails harmlessly without THP
  madvise(region, end - begin, MADV_POPULATE_WRITE);
#else
  (void)data, (void)bytes;
#endif
}

}  // namespace scanbench::core

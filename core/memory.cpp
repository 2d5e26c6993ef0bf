#include "core/memory.hpp"

#include <cstdio>
#include <fstream>
#include <string>

#include "core/errors.hpp"

namespace scanbench::core {
namespace {

std::string gigabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", static_cast<double>(bytes) / 1e9);
  return text;
}

}  // namespace

std::optional<std::uint64_t> available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  std::uint64_t value = 0;
  while (meminfo >> key >> value) {
    std::getline(meminfo, unit);
    if (key == "MemAvailable:") return value * 1024;  // reported in kB
  }
  return std::nullopt;
}

void check_memory(std::uint64_t bytes, const std::string& file) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (available && bytes > *available) {
    throw RuntimeFailure(file, {},
                         "reading it needs " + gigabytes(bytes) + " of memory, " +
                             gigabytes(*available) + " are available");
  }
}

}  // namespace scanbench::core

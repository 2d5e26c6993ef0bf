// Refusing work that cannot fit in memory before allocating for it: a file
// header that declares 2 billion points must not end in std::bad_alloc
// (or the kernel's out-of-memory killer) halfway through.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace scanbench::core {

// The memory this process can still be given [bytes]: the least of the
// system's (MemAvailable of /proc/meminfo), what the memory cgroups of the
// process and their ancestors still allow (v1 or v2: limit less usage,
// reclaimable file cache not counted as used), and what RLIMIT_AS leaves of
// the address space. None where none of them can be told.
std::optional<std::uint64_t> available_memory_bytes();

// Throws MemoryShortage naming `file` and saying "reading it needs N GB of
// memory, M GB are available" when `bytes` exceeds what is available.
// Nothing happens where the available memory cannot be told.
void check_memory(std::uint64_t bytes, const std::string& file);

}  // namespace scanbench::core

// Refusing work that cannot fit in memory before allocating for it: a file
// header that declares 2 billion points must not end in std::bad_alloc
// (or the kernel's out-of-memory killer) halfway through.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace scanbench::core {

// The memory the system can give this process now [bytes] (Linux:
// MemAvailable of /proc/meminfo); none where it cannot be told.
std::optional<std::uint64_t> available_memory_bytes();

// Throws RuntimeFailure naming `file` and saying "reading it needs N GB of
// memory, M GB are available" when `bytes` exceeds what is available.
// Nothing happens where the available memory cannot be told.
void check_memory(std::uint64_t bytes, const std::string& file);

}  // namespace scanbench::core

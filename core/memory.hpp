// Refusing work that cannot fit in memory before allocating for it: a file
// header that declares 2 billion points must not end in std::bad_alloc
// (or the kernel's out-of-memory killer) halfway through. And mapping a
// large fresh array in bulk rather than a page fault at a time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace scanbench::core {

// "1.5 GB": a memory size in messages (decimal gigabytes, one decimal).
std::string gigabytes(std::uint64_t bytes);

// The memory this process can still be given [bytes]: the least of the
// system's (MemAvailable of /proc/meminfo), what the memory cgroups of the
// process and their ancestors still allow (v1 or v2: limit less usage,
// reclaimable file cache not counted as used), and what RLIMIT_AS leaves of
// the address space. None where none of them can be told.
std::optional<std::uint64_t> available_memory_bytes();

// The most memory this process has had resident since it started
// [bytes]: the kernel's high-water mark (VmHWM of /proc/self/status), for
// this program image only (a parent's pages before exec do not count).
// None where it cannot be read.
std::optional<std::uint64_t> peak_resident_bytes();

// Throws MemoryShortage naming `file` and saying "reading it needs N GB of
// memory, M GB are available" when `bytes` exceeds what is available.
// Nothing happens where the available memory cannot be told.
void check_memory(std::uint64_t bytes, const std::string& file);

// Throws MemoryShortage naming `file` when `bytes`, what `stage` needs for
// `what`, exceed its memory limit `limit`: "STAGE needs about N GB for
// WHAT, more than its memory limit of L GB (--memory-limit)".
void check_memory_limit(std::uint64_t bytes, std::uint64_t limit, const std::string& file,
                        const std::string& stage, const std::string& what);

// Backs the pages of [data, data + bytes) with memory now, in one system
// call and in 2 MB pages where the kernel allows them (Linux: transparent
// huge pages on madvise, MADV_POPULATE_WRITE from 5.14), instead of one page
// fault per 4 KB at the first write: on a virtual machine the faults of a
// fresh array can cost more than filling it. A no-op elsewhere or on
// failure; for arrays of megabytes that are about to be written in full.
void map_now(const void* data, std::size_t bytes);

// v.reserve(n), the storage mapped in bulk.
template <typename T>
void reserve_mapped(std::vector<T>& v, std::size_t n) {
  v.reserve(n);
  map_now(v.data(), n * sizeof(T));
}

// v.assign(n, value), its storage mapped in bulk first.
template <typename T>
void assign_mapped(std::vector<T>& v, std::size_t n, const T& value) {
  reserve_mapped(v, n);
  v.assign(n, value);
}

}  // namespace scanbench::core

// Cheaper first touch for the geometry stage's large per-pixel arrays
// (tens of MB per scan, allocated per call and written once): a 4 KB page
// fault per 4 KB cost the stage about a sixth of its time.
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace scanbench::acquisition {

// A hint that the memory [data, data + bytes), not yet written, will be
// written whole soon: on Linux with transparent huge pages ("madvise" or
// "always" mode) its aligned 2 MB blocks are then faulted in as huge pages.
// Never changes the contents; a no-op elsewhere or when the kernel declines.
inline void advise_huge_pages(const void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{1} << 21;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + kHuge - 1) & ~(kHuge - 1);
  const std::uintptr_t last = (begin + bytes) & ~(kHuge - 1);
  if (last > first) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#else
  (void)data, (void)bytes;
#endif
}

}  // namespace scanbench::acquisition

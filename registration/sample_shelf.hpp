// The sample clouds of a registration's scans, one a scan, with only the
// few in use in memory: every cloud is parked in a temporary file as it is
// put, and read back when asked for after it has left memory. So a
// registration holds the samples of the scans at hand, not of the whole
// campaign (a scan's ICP samples take up to 1.3 MB).
#pragma once

#include <cstddef>

#include "core/spill_shelf.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

using SampleShelf = core::SpillShelf<SampleCloud>;

// The clouds a registration's shelves keep in memory besides those in use.
inline constexpr std::size_t kSamplesKept = 16;

}  // namespace scanbench::registration

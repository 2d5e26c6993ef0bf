// The scan_channels table: one zstd blob per channel of a scan. Internal to
// modeling/ (used by project_scans.cpp only).
//
// Channels and their element counts for a rows x columns scan (n pixels):
//   range_m     n floats [m]
//   valid       n bytes
//   intensity   n floats          only when the scan has intensity
//   rgb         3n bytes          only when the scan has color
//   directions  n Vector3f        only for per-pixel angle models
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <string>

#include "acquisition/scan.hpp"

namespace scanbench::modeling {

// Compresses and stores every channel of `scan` under scan id `id`, inside
// the caller's transaction. Throws core::InputError when SQLite fails.
void insert_channels(sqlite3* db, const std::string& file, std::int64_t id,
                     const acquisition::Scan& scan);

// Fills the channels of `scan`, whose rows, columns and angle model are
// already set from the scans row; `has_intensity` / `has_color` are that
// row's flags. Throws core::InputError naming the scan and channel
// when a channel is missing, unexpected, of the wrong size or damaged.
void read_channels(sqlite3* db, const std::string& file, std::int64_t id, bool has_intensity,
                   bool has_color, acquisition::Scan& scan);

}  // namespace scanbench::modeling

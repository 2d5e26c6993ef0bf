// The picked point pairs file of `scanbench register --pairs FILE`:
//
//   {"pairs": [{"source": 2, "target": 1,
//               "points": [{"source_m": [x, y, z], "target_m": [x, y, z]}, ...]}, ...]}
//
// source and target are scan ids of the project (`scanbench info`); each
// point is in its own scan's frame [m]. At least 3 points per entry.
#pragma once

#include <filesystem>
#include <vector>

#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"

namespace scanbench::app {

// Reads FILE. Throws core::InputError naming the file, the entry
// (e.g. "pairs[1].points[0].target_m") and the problem for malformed JSON,
// missing keys, non-numeric or non-finite coordinates, or fewer than 3 points.
std::vector<modeling::ProjectPicks> read_point_pairs_file(const std::filesystem::path& file);

}  // namespace scanbench::app

// Detection of mixed pixels ("veils"): returns whose beam footprint straddled
// a depth edge, so that the scanner reported one blended range floating
// between the foreground and the background surface.
#pragma once

#include <cstdint>
#include <span>

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// Writes 1 where a valid pixel is a mixed pixel, else 0, to every entry of
// `mixed` (rows × columns; asserted).
//
// Along each of four grid lines through the pixel (row, column, both
// diagonals) with valid neighbours at distance 1 and 2 on both sides, the
// pixel is mixed when its range lies strictly between its two neighbours,
// and it misses the linear continuation of each side in opposite directions
// (beyond one side's surface, short of the other's) by more than
// mixed_pixel_sigmas · σ(range) and mixed_pixel_relative · range, where the
// two continuations are a depth discontinuity apart (depth_jump_relative ·
// range). A side's continuation is the least-squares line through its
// neighbours at 1, 2 and 3 — (4·r(1) + r(2) − 2·r(3)) / 3, with 2.3 σ² of
// variance — or 2·r(1) − r(2) (5 σ²) where the third has no return. A point
// on a smooth surface, however steep or grazing, continues both sides
// linearly. The noise test finds blends a few σ off their surface where σ
// is large (a structured-light sensor: 37 mm at 5 m); the relative floor
// and the discontinuity keep fine relief (leaves, mouldings) unflagged where
// σ is a millimetre.
void detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings,
                         std::span<std::uint8_t> mixed);

}  // namespace scanbench::acquisition

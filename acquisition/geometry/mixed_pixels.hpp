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
// and it misses the linear continuation of each side — 2·r(−1) − r(−2) and
// 2·r(+1) − r(+2) — by more than mixed_pixel_sigmas · σ(range), in opposite
// directions (beyond one side's surface, short of the other's). A point on a
// smooth surface, however steep or grazing, continues both sides linearly.
void detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings,
                         std::span<std::uint8_t> mixed);

}  // namespace scanbench::acquisition

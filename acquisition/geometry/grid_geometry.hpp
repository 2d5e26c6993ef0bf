// Inside the geometry stage: the fits of a grid's pixels
// (scan_geometry.cpp), which compute_geometry and compute_geometry_rows
// (compute_geometry.cpp) run on a whole grid or a band of its rows.
#pragma once

#include "acquisition/geometry/row_band.hpp"
#include "acquisition/geometry/scan_geometry.hpp"

namespace scanbench::acquisition {

// The geometry of grid rows [band.begin, band.end) of a grid scan held in
// `scan` from grid row band.first_row (row_band.hpp), with the σ(range)
// of `settings` as it is. The result's arrays and counts are the band's
// rows'; its noise is left empty.
GeometryResult compute_grid_geometry(const Scan& scan, const GeometrySettings& settings,
                                     const RowBand& band);

}  // namespace scanbench::acquisition

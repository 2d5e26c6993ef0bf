// The user's limits on region growing (seed 004 §4.1): a closed lasso the
// region must stay inside, barrier polylines it must not cross, and the
// pixels already given to objects. Coordinates are in the panoramic image:
// x = column, y = row, pixel centres at integers. On a grid that wraps
// around, x may run past either edge (a lasso or barrier across the seam)
// and is taken modulo the column count; on other grids what lies outside is
// clipped. Vertices are unwrapped: a line across the seam goes from x =
// columns − 2 to x = columns + 2, not to x = 2 (that would be a line the
// other way round). Every vertex must be finite and lie within one grid
// size of the grid (−columns ≤ x ≤ 2·columns, −rows ≤ y ≤ 2·rows; asserted):
// callers refuse other input as bad input.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "segmentation/segmentation_grid.hpp"

namespace scanbench::segmentation {

using Polyline = std::vector<Eigen::Vector2d>;  // (x = column, y = row) vertices

// A pixel of the grid by (row, col), as the scan's arrays index it.
struct GridPixel {
  int row = 0;
  int col = 0;
};

// The pixel whose centre is nearest image point `xy` (x = column, y = row):
// the one place a click becomes (row, col). Coordinates are clamped to
// [-1, 10^9] first, so that a point far off the grid stays off it instead of
// wrapping. Asserts `xy` is finite. (Lines drawn on the grid round their
// vertices themselves: a seam-crossing barrier's x runs past the grid.)
GridPixel nearest_pixel(const Eigen::Vector2d& xy);

// Whether vertex `v` is finite and within one grid size of the grid (the
// bound above): what callers check before they hand vertices over.
bool within_reach(const GridShape& shape, const Eigen::Vector2d& v);

// Sets mask[i] = value on the pixels whose centres lie inside the closed
// polygon (even-odd rule; the edge from the last vertex back to the first
// closes it). A polygon of fewer than 3 vertices covers nothing. Asserts
// the mask has one byte per pixel and the vertices as above.
void fill_polygon(const GridShape& shape, const Polyline& polygon, std::uint8_t value,
                  std::vector<std::uint8_t>& mask);

// Sets mask[i] = value along the polyline, as a 4-connected chain of pixels
// from each vertex's nearest pixel to the next one's: no step to one of the
// 8 neighbours can pass between two of its pixels, so a region growing
// 8-connected never crosses it. A single vertex marks its pixel. Asserts as
// fill_polygon.
void draw_barrier(const GridShape& shape, const Polyline& barrier, std::uint8_t value,
                  std::vector<std::uint8_t>& mask);

struct Constraints {
  Polyline lasso;  // fewer than 3 vertices: no lasso (the whole scan)
  std::vector<Polyline> barriers;
};

// The open pixels region growing may enter (1) or not (0): usable, inside
// the lasso, off every barrier, and not `taken` (a byte per pixel, non-zero
// where an object already owns the pixel; empty: none taken). Built once per
// change of the constraints, not per click.
std::vector<std::uint8_t> open_pixels(const SegmentationGrid& grid, const Constraints& constraints,
                                      std::span<const std::uint8_t> taken);

}  // namespace scanbench::segmentation

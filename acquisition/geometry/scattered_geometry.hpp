// Per-point geometry of a scattered scan (scan.hpp), which has no grid to
// take neighbours from: each point's neighbours are its k nearest in space.
// The outputs mean what they mean for a grid (scan_geometry.hpp), so every
// later stage reads them alike.
#pragma once

#include "acquisition/geometry/scan_geometry.hpp"
#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// For every point: a plane fitted to its 16 nearest neighbours, leaving
// out those farther than 3 × the distance to its 4th nearest (across a gap,
// they sample another surface), or, where they do not span a plane above
// the noise, to its 64 nearest within 3 × the 16th's distance. Distances
// count neighbours apart from the point (more than 0.1 mm: files repeat
// points), and are at least 0.1 mm. The normal is oriented towards the scan
// frame's origin, the viewpoint as far as the file tells (a scanner's
// position, or the origin a unified cloud was exported in). The footprint
// is 3/4 of the distance to the 4th nearest neighbour (on a regular sampling of step s,
// 0.75 s closes the gap as the grid's half cell diagonal, 0.71 s, does;
// distances between points already include a slanted surface's stretch,
// so there is no incidence factor). A point whose distance to its 4th
// nearest exceeds 3 × the median of its neighbours' stands alone (a stray
// return): no normal, and a footprint of at most 3 × that median, not one
// that bridges the gap. Confidence is the share of neighbours the fit kept
// times the cosine of the incidence angle.
// Mixed pixels and depth edges are properties of a beam's neighbours in a
// grid: none is flagged.
// With settings.estimate_range_noise, the noise is estimated from the
// points (GeometryResult::noise): each point whose 16 nearest neighbours
// all span a plane gets σ = √(λ₀ / 13), λ₀ the sum of their squared
// distances to it; the cloud's σ is the 30th percentile of those, divided
// by that percentile of √(χ²₁₃ / 13) (0.874), so that rough surfaces
// (foliage, rubble) on up to about two thirds of the cloud do not drag it
// up. It is a constant: a cloud's distance from its origin need not be a
// range (a cloud unified from many stations), and it is noise across the
// surface, which is range noise times the cosine of the incidence. At least
// 0.1 mm; fewer than 100 such points keep settings.range_noise.
// Where the file `recorded` a normal, the point has it as the file has it,
// with the confidence of the cosine of its incidence; where it recorded a
// footprint, the point has that one. A cloud's origin need not be where it
// was seen from (a cloud unified from many stations), so a recorded
// normal's side, which faces the scanner that saw the surface, is kept
// rather than turned to the origin; a fitted normal among recorded ones
// takes their side, so that neighbours agree (registration's matches,
// picking and backface culling compare sides).
// Asserts scan.is_scattered() and each of `recorded` empty or one per pixel.
GeometryResult compute_scattered_geometry(const Scan& scan, const GeometrySettings& settings,
                                          const RecordedGeometry& recorded = {});

// The surface [m²] a point of a scattered scan stands for: the square of
// the sampling step its footprint was made from.
float scattered_sample_area_m2(float footprint_m);

}  // namespace scanbench::acquisition

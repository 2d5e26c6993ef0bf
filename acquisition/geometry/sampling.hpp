// How much surface one sample of a scan stands for (seed 004 §4.3): the
// inverse of the local sampling rate, which the merge compares between scans
// and the renderer turns into splat sizes.
#pragma once

#include <algorithm>
#include <cmath>

#include "acquisition/scan.hpp"

namespace scanbench::acquisition {

// |cos incidence| below this (incidence above ~87°) counts as this: a sample
// seen edge-on does not stand for an unbounded area.
inline constexpr float kMinCosIncidence = 0.05f;

// Solid angle [sr] of the cell of pixel (row, col): the parallelogram spanned
// by the direction steps to the next column and row (to the previous ones at
// the last column or row). For spherical grids this is |Δaz · Δel| · cos el,
// the same for a whole row. 0 for a grid of one row or one column, and where
// a per-pixel direction is unknown. Asserts (row, col) lies in the grid.
float pixel_solid_angle(const Scan& scan, int row, int col);

// Surface area [m²] that a sample at `range_m` [m] in a cell of
// `solid_angle_sr` [sr] stands for, seen at incidence cos_incidence (the
// cosine between beam and normal; pass 1 when the normal is unknown):
// range² · Ω / max(|cos incidence|, kMinCosIncidence).
inline float sample_area_m2(float range_m, float solid_angle_sr, float cos_incidence) {
  return range_m * range_m * solid_angle_sr / std::max(std::abs(cos_incidence), kMinCosIncidence);
}

}  // namespace scanbench::acquisition

#include "registration/prepared_scan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "core/parallel.hpp"

namespace scanbench::registration {
namespace {

// |cos incidence| below this (incidence above ~87°) counts as this: a sample
// seen edge-on does not stand for an unbounded area.
constexpr float kMinCosIncidence = 0.05f;

// Solid angle [sr] of the pixel cell: the parallelogram spanned by the
// direction steps to the next column and row (to the previous ones at the
// last column or row). For spherical grids this is |Δaz · Δel| · cos el.
float solid_angle(const acquisition::Scan& scan, int row, int col) {
  const int next_col = col + 1 < scan.columns ? col + 1 : col - 1;
  const int next_row = row + 1 < scan.rows ? row + 1 : row - 1;
  if (next_col < 0 || next_row < 0) return 0.0f;
  const Eigen::Vector3f d = acquisition::direction(scan, row, col);
  const Eigen::Vector3f along_row = acquisition::direction(scan, row, next_col) - d;
  const Eigen::Vector3f along_col = acquisition::direction(scan, next_row, col) - d;
  return along_row.cross(along_col).norm();
}

void prepare_row(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry, int row,
                 PreparedScan& out) {
  // Spherical grids share one solid angle per row.
  const float row_solid_angle = scan.is_spherical() ? solid_angle(scan, row, 0) : 0.0f;
  for (int col = 0; col < scan.columns; ++col) {
    const std::size_t i = scan.index(row, col);
    if (!scan.valid[i] || geometry.is_mixed(i)) continue;
    const Eigen::Vector3f d = acquisition::direction(scan, row, col);
    const float range = scan.range_m[i];
    out.points[i] = range * d;
    out.in_model[i] = 1;
    out.usable[i] = geometry.has_normal(i) ? 1 : 0;
    const float cos_incidence =
        out.usable[i] ? std::max(std::abs(geometry.normal[i].dot(d)), kMinCosIncidence) : 1.0f;
    const float omega = scan.is_spherical() ? row_solid_angle : solid_angle(scan, row, col);
    out.sample_area_m2[i] = range * range * omega / cos_incidence;
  }
}

}  // namespace

PreparedScan prepare_scan(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry,
                          int threads) {
  const std::size_t n = scan.pixel_count();
  assert(geometry.normal.size() == n && geometry.flags.size() == n &&
         "geometry must belong to the scan");
  PreparedScan out;
  out.scan = &scan;
  out.geometry = &geometry;
  out.points.assign(n, Eigen::Vector3f::Zero());
  out.in_model.assign(n, 0);
  out.usable.assign(n, 0);
  out.sample_area_m2.assign(n, 0.0f);
  core::parallel_for_index(
      scan.rows, threads, [&](int row) { prepare_row(scan, geometry, row, out); }, 8);
  if (scan.is_spherical()) {
    out.grid.emplace(scan);
  } else {
    out.tree = std::make_unique<PointIndex>(out.points, out.usable);
  }
  return out;
}

std::int64_t associate(const PreparedScan& target, const Eigen::Vector3f& p_target) {
  if (target.grid) return target.grid->pixel_of(p_target);
  return target.tree->nearest(p_target);
}

}  // namespace scanbench::registration

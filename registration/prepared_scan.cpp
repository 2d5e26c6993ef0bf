#include "registration/prepared_scan.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <optional>

#include "acquisition/geometry/sampling.hpp"
#include "acquisition/geometry/scattered_geometry.hpp"
#include "core/memory.hpp"
#include "core/parallel.hpp"

namespace scanbench::registration {
namespace {

// `spherical`: the scan's directions, for a spherical grid (else nullptr).
void prepare_row(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry,
                 const acquisition::SphericalDirections* spherical, int row, PreparedScan& out) {
  // Spherical grids share one solid angle per row.
  const float row_solid_angle =
      scan.is_spherical() ? acquisition::pixel_solid_angle(scan, row, 0) : 0.0f;
  for (int col = 0; col < scan.columns; ++col) {
    const std::size_t i = scan.index(row, col);
    if (!acquisition::in_model(scan, geometry, i)) continue;
    const Eigen::Vector3f d =
        spherical != nullptr ? (*spherical)(row, col) : acquisition::direction(scan, row, col);
    const float range = scan.range_m[i];
    if (!out.points.empty()) out.points[i] = range * d;
    out.in_model[i] = 1;
    out.usable[i] = geometry.has_normal(i) ? 1 : 0;
    const float cos_incidence = out.usable[i] ? geometry.normal[i].dot(d) : 1.0f;
    if (scan.is_scattered()) {
      out.sample_area_m2[i] = acquisition::scattered_sample_area_m2(geometry.footprint_m[i]);
      continue;
    }
    const float omega =
        scan.is_spherical() ? row_solid_angle : acquisition::pixel_solid_angle(scan, row, col);
    out.sample_area_m2[i] = acquisition::sample_area_m2(range, omega, cos_incidence);
  }
}

}  // namespace

PreparedScan prepare_scan(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry,
                          int threads, GridPoints grid_points) {
  const std::size_t n = scan.pixel_count();
  assert(geometry.normal.size() == n && geometry.flags.size() == n &&
         "geometry must belong to the scan");
  PreparedScan out;
  out.scan = &scan;
  out.geometry = &geometry;
  const bool with_points = !scan.is_spherical() || grid_points == GridPoints::kComputed;
  if (with_points) core::assign_mapped(out.points, n, Eigen::Vector3f::Zero().eval());
  core::assign_mapped(out.in_model, n, std::uint8_t{0});
  core::assign_mapped(out.usable, n, std::uint8_t{0});
  core::assign_mapped(out.sample_area_m2, n, 0.0f);
  std::optional<acquisition::SphericalDirections> spherical;
  if (scan.is_spherical()) spherical.emplace(scan);
  core::parallel_for_index(
      scan.rows, threads,
      [&](int row) { prepare_row(scan, geometry, spherical ? &*spherical : nullptr, row, out); },
      8);
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

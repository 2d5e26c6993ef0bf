#include "acquisition/scan_summary.hpp"

namespace scanbench::acquisition {

ScanSummary summarize(const Scan& scan) {
  ScanSummary summary;
  summary.name = scan.name;
  summary.rows = scan.rows;
  summary.columns = scan.columns;
  summary.valid_points = count_valid(scan);
  summary.has_color = scan.has_color();
  summary.has_intensity = scan.has_intensity();
  summary.spherical = scan.is_spherical();
  summary.scattered = scan.is_scattered();
  summary.T_world_scan = scan.T_world_scan;
  summary.bbox_world = world_bounds(scan);
  summary.scanner = scan.scanner;
  return summary;
}

const char* angle_model_name(bool spherical) {
  return spherical ? "spherical" : "per_pixel";
}

}  // namespace scanbench::acquisition

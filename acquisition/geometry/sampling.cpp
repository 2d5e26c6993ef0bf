#include "acquisition/geometry/sampling.hpp"

namespace scanbench::acquisition {

float pixel_solid_angle(const Scan& scan, int row, int col) {
  const int next_col = col + 1 < scan.columns ? col + 1 : col - 1;
  const int next_row = row + 1 < scan.rows ? row + 1 : row - 1;
  if (next_col < 0 || next_row < 0) return 0.0f;
  const Eigen::Vector3f d = direction(scan, row, col);
  const Eigen::Vector3f along_row = direction(scan, row, next_col) - d;
  const Eigen::Vector3f along_col = direction(scan, next_row, col) - d;
  return along_row.cross(along_col).norm();
}

}  // namespace scanbench::acquisition

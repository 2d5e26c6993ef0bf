#include "acquisition/mixed_pixels.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>

namespace scanbench::acquisition {
namespace {

struct Line {
  int dr;
  int dc;
};
constexpr Line kLines[4] = {{0, 1}, {1, 0}, {1, 1}, {1, -1}};

// Range at (row, col), or a negative value when outside the grid or invalid.
float range_at(const Scan& scan, int row, int col) {
  if (row < 0 || row >= scan.rows || col < 0 || col >= scan.columns) return -1.0f;
  const std::size_t i = scan.index(row, col);
  return scan.valid[i] ? scan.range_m[i] : -1.0f;
}

bool mixed_along(const Scan& scan, int row, int col, Line line, double threshold) {
  const float c = range_at(scan, row, col);
  const float a1 = range_at(scan, row - line.dr, col - line.dc);
  const float a2 = range_at(scan, row - 2 * line.dr, col - 2 * line.dc);
  const float b1 = range_at(scan, row + line.dr, col + line.dc);
  const float b2 = range_at(scan, row + 2 * line.dr, col + 2 * line.dc);
  if (a1 < 0 || a2 < 0 || b1 < 0 || b2 < 0) return false;
  const bool between = (a1 < c && c < b1) || (b1 < c && c < a1);
  if (!between) return false;
  const double miss_a = c - (2.0 * a1 - a2);  // off the continuation of side a
  const double miss_b = c - (2.0 * b1 - b2);
  return std::abs(miss_a) > threshold && std::abs(miss_b) > threshold && miss_a * miss_b < 0.0;
}

}  // namespace

std::vector<std::uint8_t> detect_mixed_pixels(const Scan& scan, const GeometrySettings& settings) {
  std::vector<std::uint8_t> mixed(scan.pixel_count(), 0);
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int>(0, scan.rows), [&](const tbb::blocked_range<int>& rows) {
          for (int row = rows.begin(); row < rows.end(); ++row) {
            for (int col = 0; col < scan.columns; ++col) {
              const std::size_t i = scan.index(row, col);
              if (!scan.valid[i]) continue;
              const double sigma =
                  settings.range_noise_m + settings.range_noise_per_m * scan.range_m[i];
              const double threshold = settings.mixed_pixel_sigmas * sigma;
              for (const Line& line : kLines) {
                if (mixed_along(scan, row, col, line, threshold)) {
                  mixed[i] = 1;
                  break;
                }
              }
            }
          }
        });
  });
  return mixed;
}

}  // namespace scanbench::acquisition

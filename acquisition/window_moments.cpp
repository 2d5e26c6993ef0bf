#include "acquisition/window_moments.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <cassert>

namespace scanbench::acquisition {
namespace {

// Running window sums of a, d·a and d²·a for d in [−k, k], advanced by one
// sample: `out` leaves the window, `in` enters it. Derivation: re-index the
// shifted window (e = d + 1) and expand (e − 1) and (e − 1)².
struct Running {
  double s0 = 0, s1 = 0, s2 = 0;

  void advance(double out, double in, int k) {
    const double kk = k, k1 = k + 1.0;
    const double s0_old = s0, s1_old = s1;
    s0 = s0_old - out + in;
    s1 = s1_old - s0_old + k1 * out + kk * in;
    s2 = s2 - 2.0 * s1_old + s0_old - k1 * k1 * out + kk * kk * in;
  }
};

// The six per-row inputs of the vertical pass.
enum Horizontal { kM, kMx, kMxx, kV, kVx, kHorizontalCount };
using RowSums = std::array<float, kHorizontalCount>;

template <typename Body>
void parallel_ranges(int count, int threads, Body&& body) {
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, count, 64),
                      [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
  });
}

// Sums along one row: m, m·dx, m·dx², m·v, m·dx·v.
void horizontal_row(int columns, int k, const std::uint8_t* mask, const float* value,
                    RowSums* out) {
  Running m, v;
  const auto sample = [&](int c, double& mi, double& vi) {
    mi = vi = 0;
    if (c < 0 || c >= columns || !mask[c]) return;
    mi = 1;
    vi = value[c];
  };
  double mi, vi;
  for (int c = -k; c <= k; ++c) {  // the window of column 0, built explicitly
    sample(c, mi, vi);
    m.s0 += mi, m.s1 += c * mi, m.s2 += c * c * mi;
    v.s0 += vi, v.s1 += c * vi;
  }
  for (int c = 0; c < columns; ++c) {
    out[c] = {static_cast<float>(m.s0), static_cast<float>(m.s1), static_cast<float>(m.s2),
              static_cast<float>(v.s0), static_cast<float>(v.s1)};
    double mo, vo;
    sample(c - k, mo, vo);
    sample(c + k + 1, mi, vi);
    m.advance(mo, mi, k);
    v.advance(vo, vi, k);
  }
}

// Running vertical sums for one column: each horizontal input gets the dy
// weights it needs (m: 1, dy, dy²; m·dx: 1, dy; m·v: 1, dy; others: 1).
struct ColumnState {
  Running m, mx, v;
  double mxx = 0, vx = 0;

  void add(const RowSums& h, int dy) {
    m.s0 += h[kM], m.s1 += dy * h[kM], m.s2 += dy * dy * h[kM];
    mx.s0 += h[kMx], mx.s1 += dy * h[kMx];
    v.s0 += h[kV], v.s1 += dy * h[kV];
    mxx += h[kMxx], vx += h[kVx];
  }
  void advance(const RowSums& out, const RowSums& in, int k) {
    m.advance(out[kM], in[kM], k);
    mx.advance(out[kMx], in[kMx], k);
    v.advance(out[kV], in[kV], k);
    mxx += in[kMxx] - out[kMxx], vx += in[kVx] - out[kVx];
  }
  WindowMoments moments() const {
    const auto f = [](double x) { return static_cast<float>(x); };
    return {f(m.s0), f(mx.s0), f(m.s1), f(mxx), f(mx.s1), f(m.s2), f(v.s0), f(vx), f(v.s1)};
  }
};

}  // namespace

std::vector<WindowMoments> window_moments(int rows, int columns, int radius,
                                          std::span<const std::uint8_t> mask,
                                          std::span<const float> value, int threads) {
  const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(mask.size() == n && value.size() == n && radius >= 1);
  std::vector<RowSums> horizontal(n);
  parallel_ranges(rows, threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      const std::size_t o = static_cast<std::size_t>(r) * columns;
      horizontal_row(columns, radius, mask.data() + o, value.data() + o, horizontal.data() + o);
    }
  });
  std::vector<WindowMoments> result(n);
  const RowSums zero{};
  const auto row_sums = [&](int r, int c) -> const RowSums& {
    return r < 0 || r >= rows ? zero : horizontal[static_cast<std::size_t>(r) * columns + c];
  };
  parallel_ranges(columns, threads, [&](int begin, int end) {
    for (int c = begin; c < end; ++c) {
      ColumnState state;
      for (int dy = -radius; dy <= radius; ++dy) state.add(row_sums(dy, c), dy);
      for (int r = 0; r < rows; ++r) {
        result[static_cast<std::size_t>(r) * columns + c] = state.moments();
        state.advance(row_sums(r - radius, c), row_sums(r + radius + 1, c), radius);
      }
    }
  });
  return result;
}

std::vector<std::uint16_t> window_counts(int rows, int columns, int radius,
                                         std::span<const std::uint8_t> mask, int threads) {
  const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(mask.size() == n && radius >= 1 && (2 * radius + 1) * (2 * radius + 1) < 65536);
  std::vector<std::uint16_t> horizontal(n), counts(n);
  parallel_ranges(rows, threads, [&](int begin, int end) {
    for (int r = begin; r < end; ++r) {
      const std::uint8_t* m = mask.data() + static_cast<std::size_t>(r) * columns;
      const auto at = [&](int c) { return c < 0 || c >= columns ? 0 : (m[c] ? 1 : 0); };
      int sum = 0;
      for (int c = -radius; c <= radius; ++c) sum += at(c);
      for (int c = 0; c < columns; ++c) {
        horizontal[static_cast<std::size_t>(r) * columns + c] = static_cast<std::uint16_t>(sum);
        sum += at(c + radius + 1) - at(c - radius);
      }
    }
  });
  parallel_ranges(columns, threads, [&](int begin, int end) {
    for (int c = begin; c < end; ++c) {
      const auto at = [&](int r) {
        return r < 0 || r >= rows ? 0 : horizontal[static_cast<std::size_t>(r) * columns + c];
      };
      int sum = 0;
      for (int r = -radius; r <= radius; ++r) sum += at(r);
      for (int r = 0; r < rows; ++r) {
        counts[static_cast<std::size_t>(r) * columns + c] = static_cast<std::uint16_t>(sum);
        sum += at(r + radius + 1) - at(r - radius);
      }
    }
  });
  return counts;
}

}  // namespace scanbench::acquisition

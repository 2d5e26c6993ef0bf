#include "acquisition/window_moments.hpp"

#include <algorithm>
#include <array>
#include <cassert>

#include "acquisition/parallel.hpp"

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

// The five per-row inputs of the vertical pass.
enum Horizontal { kM, kMx, kMxx, kV, kVx, kHorizontalCount };
using RowSums = std::array<float, kHorizontalCount>;

// Column blocks: wide enough that a block's running state stays in cache,
// many enough for the threads to share the work.
constexpr int kBlockColumns = 256;

template <typename Body>
void parallel_blocks(int columns, int threads, Body&& body) {
  const int blocks = (columns + kBlockColumns - 1) / kBlockColumns;
  parallel_for_index(blocks, threads, [&](int b) {
    body(b * kBlockColumns, std::min(columns, (b + 1) * kBlockColumns));
  });
}

// Sums along one row for columns [begin, end): m, m·dx, m·dx², m·v, m·dx·v.
void horizontal_row(int columns, int begin, int end, int k, const std::uint8_t* mask,
                    const float* value, RowSums* out) {
  Running m, v;
  const auto sample = [&](int c, double& mi, double& vi) {
    mi = vi = 0;
    if (c < 0 || c >= columns || !mask[c]) return;
    mi = 1;
    vi = value[c];
  };
  double mi, vi;
  for (int d = -k; d <= k; ++d) {  // the window of the first column, built explicitly
    sample(begin + d, mi, vi);
    m.s0 += mi, m.s1 += d * mi, m.s2 += d * d * mi;
    v.s0 += vi, v.s1 += d * vi;
  }
  for (int c = begin; c < end; ++c) {
    out[c - begin] = {static_cast<float>(m.s0), static_cast<float>(m.s1), static_cast<float>(m.s2),
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

// The horizontal sums of rows [row − k, row + k + 1] for one column block,
// kept in a ring of 2k + 2 rows: the vertical pass needs the row leaving and
// the row entering the window.
class RowRing {
 public:
  RowRing(int rows, int columns, int begin, int end, int k, std::span<const std::uint8_t> mask,
          std::span<const float> value)
      : rows_(rows),
        columns_(columns),
        begin_(begin),
        width_(end - begin),
        k_(k),
        mask_(mask),
        value_(value),
        slots_(2 * k + 2),
        data_(static_cast<std::size_t>(slots_) * width_) {}

  // Horizontal sums of `row` (zeros outside the grid), computed once per row.
  const RowSums* row(int r) {
    RowSums* slot =
        data_.data() + static_cast<std::size_t>(((r % slots_) + slots_) % slots_) * width_;
    if (r < 0 || r >= rows_) {
      std::fill(slot, slot + width_, RowSums{});
    } else if (r != filled_[((r % slots_) + slots_) % slots_]) {
      const std::size_t o = static_cast<std::size_t>(r) * columns_;
      horizontal_row(columns_, begin_, begin_ + width_, k_, mask_.data() + o, value_.data() + o,
                     slot);
    }
    filled_[((r % slots_) + slots_) % slots_] = r;
    return slot;
  }

 private:
  int rows_, columns_, begin_, width_, k_;
  std::span<const std::uint8_t> mask_;
  std::span<const float> value_;
  int slots_;
  std::vector<RowSums> data_;
  std::vector<int> filled_ = std::vector<int>(static_cast<std::size_t>(slots_), -1 << 30);
};

}  // namespace

void visit_window_moments(int rows, int columns, int radius, std::span<const std::uint8_t> mask,
                          std::span<const float> value, int threads, const MomentsVisitor& visit) {
  assert(mask.size() == static_cast<std::size_t>(rows) * columns && value.size() == mask.size() &&
         radius >= 1);
  parallel_blocks(columns, threads, [&](int begin, int end) {
    const int width = end - begin;
    RowRing ring(rows, columns, begin, end, radius, mask, value);
    std::vector<ColumnState> state(static_cast<std::size_t>(width));
    for (int dy = -radius; dy <= radius; ++dy) {
      const RowSums* h = ring.row(dy);
      for (int c = 0; c < width; ++c) state[c].add(h[c], dy);
    }
    std::vector<WindowMoments> out(static_cast<std::size_t>(width));
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < width; ++c) out[c] = state[c].moments();
      visit(r, begin, end, out.data());
      const RowSums* leaving = ring.row(r - radius);
      const RowSums* entering = ring.row(r + radius + 1);
      for (int c = 0; c < width; ++c) state[c].advance(leaving[c], entering[c], radius);
    }
  });
}

std::vector<WindowMoments> window_moments(int rows, int columns, int radius,
                                          std::span<const std::uint8_t> mask,
                                          std::span<const float> value, int threads) {
  std::vector<WindowMoments> result(static_cast<std::size_t>(rows) * columns);
  visit_window_moments(rows, columns, radius, mask, value, threads,
                       [&](int row, int begin, int end, const WindowMoments* moments) {
                         std::copy(
                             moments, moments + (end - begin),
                             result.begin() + static_cast<std::ptrdiff_t>(row) * columns + begin);
                       });
  return result;
}

std::vector<std::uint16_t> window_counts(int rows, int columns, int radius,
                                         std::span<const std::uint8_t> mask, int threads) {
  const std::size_t n = static_cast<std::size_t>(rows) * columns;
  assert(mask.size() == n && radius >= 1 && (2 * radius + 1) * (2 * radius + 1) < 65536);
  std::vector<std::uint16_t> horizontal(n), counts(n);
  parallel_for_index(
      rows, threads,
      [&](int r) {
        const std::uint8_t* m = mask.data() + static_cast<std::size_t>(r) * columns;
        const auto at = [&](int c) { return c < 0 || c >= columns ? 0 : (m[c] ? 1 : 0); };
        int sum = 0;
        for (int c = -radius; c <= radius; ++c) sum += at(c);
        for (int c = 0; c < columns; ++c) {
          horizontal[static_cast<std::size_t>(r) * columns + c] = static_cast<std::uint16_t>(sum);
          sum += at(c + radius + 1) - at(c - radius);
        }
      },
      16);
  parallel_blocks(columns, threads, [&](int begin, int end) {
    std::vector<int> sum(static_cast<std::size_t>(end - begin), 0);
    const auto row = [&](int r) -> const std::uint16_t* {
      return r < 0 || r >= rows ? nullptr
                                : horizontal.data() + static_cast<std::size_t>(r) * columns;
    };
    for (int r = -radius; r <= radius; ++r) {
      if (const std::uint16_t* h = row(r)) {
        for (int c = begin; c < end; ++c) sum[c - begin] += h[c];
      }
    }
    for (int r = 0; r < rows; ++r) {
      std::uint16_t* out = counts.data() + static_cast<std::size_t>(r) * columns;
      for (int c = begin; c < end; ++c) out[c] = static_cast<std::uint16_t>(sum[c - begin]);
      if (const std::uint16_t* leaving = row(r - radius)) {
        for (int c = begin; c < end; ++c) sum[c - begin] -= leaving[c];
      }
      if (const std::uint16_t* entering = row(r + radius + 1)) {
        for (int c = begin; c < end; ++c) sum[c - begin] += entering[c];
      }
    }
  });
  return counts;
}

}  // namespace scanbench::acquisition

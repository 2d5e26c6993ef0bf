#include "registration/color_harmonization.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>

#include "acquisition/color_space.hpp"
#include "core/parallel.hpp"
#include "registration/color_costs.hpp"
#include "registration/color_solver.hpp"

namespace scanbench::registration {

namespace {

constexpr std::array<std::string_view, 2> kModelNames = {"gain-offset", "matrix"};

bool usable_color(const acquisition::Scan& scan, std::size_t i, const ColorPairSettings& s) {
  for (int c = 0; c < 3; ++c) {
    const int v = scan.rgb[3 * i + static_cast<std::size_t>(c)];
    if (v <= s.dark || v >= s.bright) return false;
  }
  return true;
}

// Whether pixel i's colour is within `limit` of its valid 4-neighbours'.
// A scattered scan's pixels are not neighbours: its points count as
// uniform (the pair's colours are still checked against each other).
bool locally_uniform(const acquisition::Scan& scan, std::size_t i, int limit) {
  if (scan.is_scattered()) return true;
  const int row = static_cast<int>(i / static_cast<std::size_t>(scan.columns));
  const int col = static_cast<int>(i % static_cast<std::size_t>(scan.columns));
  const std::array<std::array<int, 2>, 4> steps = {{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  for (const auto& [dr, dc] : steps) {
    const int r = row + dr, c = col + dc;
    if (r < 0 || r >= scan.rows || c < 0 || c >= scan.columns) continue;
    const std::size_t n = scan.index(r, c);
    if (!scan.valid[n]) continue;
    for (std::size_t ch = 0; ch < 3; ++ch) {
      if (std::abs(int{scan.rgb[3 * i + ch]} - int{scan.rgb[3 * n + ch]}) > limit) return false;
    }
  }
  return true;
}

Eigen::Vector3f linear_color(const acquisition::Scan& scan, std::size_t i) {
  return {acquisition::srgb_to_linear(scan.rgb[3 * i]),
          acquisition::srgb_to_linear(scan.rgb[3 * i + 1]),
          acquisition::srgb_to_linear(scan.rgb[3 * i + 2])};
}

// Pairs from a's samples into b, in a's row order: chunks of samples on
// the workers, joined in order.
std::vector<ColorPair> pairs_between(const ColorSamples& a, const PreparedScan& b, std::uint32_t ia,
                                     std::uint32_t ib, const Eigen::Isometry3f& T_b_a,
                                     const ColorPairSettings& s) {
  const acquisition::Scan& scan_b = *b.scan;
  const double min_cos = std::cos(s.max_normal_angle_deg * 3.14159265358979323846 / 180.0);
  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (a.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<ColorPair>> by_chunk(chunks);
  core::parallel_for_index(static_cast<int>(chunks), s.threads, [&](int c) {
    const std::size_t begin = static_cast<std::size_t>(c) * kChunk;
    const std::size_t end = std::min(a.size(), begin + kChunk);
    for (std::size_t k = begin; k < end; ++k) {
      const Eigen::Vector3f p = T_b_a * a.points[k];
      const std::int64_t found = associate(b, p);
      if (found < 0) continue;
      const auto j = static_cast<std::size_t>(found);
      if (!b.in_model[j] || !usable_color(scan_b, j, s) ||
          !locally_uniform(scan_b, j, s.max_local_step))
        continue;
      const double reach = s.max_distance_m + 2.0 * b.geometry->footprint_m[j];
      if ((p - b.points[j]).norm() > reach) continue;
      const Eigen::Vector3f& na = a.normals[k];
      const Eigen::Vector3f& nb = b.geometry->normal[j];
      if (na.squaredNorm() > 0.25f && nb.squaredNorm() > 0.25f &&
          (T_b_a.linear() * na).dot(nb) < min_cos)
        continue;
      by_chunk[static_cast<std::size_t>(c)].push_back(
          {ia, ib, a.pixels[k], found, a.rgb[k], linear_color(scan_b, j)});
    }
  });
  std::vector<ColorPair> out;
  for (const std::vector<ColorPair>& chunk : by_chunk)
    out.insert(out.end(), chunk.begin(), chunk.end());
  return out;
}

// Per scan, the fixed scan of its group of scans linked by pairs (the one
// with the lowest index), or -1 for a scan in no pair.
std::vector<std::int32_t> group_references(std::span<const ColorPair> pairs, std::size_t count) {
  std::vector<std::size_t> root(count);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](std::size_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  std::vector<std::uint8_t> paired(count, 0);
  for (const ColorPair& p : pairs) {
    paired[p.scan_a] = paired[p.scan_b] = 1;
    // The smaller root wins, so every group's root is its lowest index.
    const std::size_t a = find(p.scan_a), b = find(p.scan_b);
    root[std::max(a, b)] = std::min(a, b);
  }
  std::vector<std::int32_t> out(count, -1);
  for (std::size_t k = 0; k < count; ++k)
    if (paired[k]) out[k] = static_cast<std::int32_t>(find(k));
  return out;
}

acquisition::ColorCorrection correction_of(const std::vector<double>& p, ColorModel model) {
  acquisition::ColorCorrection c;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      const int i = costs::matrix_parameter(model, row, col);
      if (i >= 0) c.matrix(row, col) = p[static_cast<std::size_t>(i)];
    }
    c.offset[row] = p[static_cast<std::size_t>(costs::offset_parameter(model, row))];
  }
  return c;
}

}  // namespace

std::string_view color_model_name(ColorModel model) {
  return kModelNames[static_cast<std::size_t>(model)];
}

std::size_t link_pair_budget(const ColorPairSettings& settings, std::size_t partners_a,
                             std::size_t partners_b) {
  std::size_t budget = settings.max_pairs_per_overlap;  // 0: all
  if (settings.max_pairs_per_scan > 0) {
    const std::size_t busier = std::max<std::size_t>({partners_a, partners_b, 1});
    const std::size_t share = std::max<std::size_t>(settings.max_pairs_per_scan / busier, 1);
    budget = budget == 0 ? share : std::min(budget, share);
  }
  return budget;
}

ColorSamples color_samples(const PreparedScan& scan, const ColorPairSettings& settings) {
  const acquisition::Scan& a = *scan.scan;
  if (!a.has_color()) return {};
  const int stride = std::max(1, settings.stride);
  const int phase = std::clamp(settings.phase, 0, stride - 1);
  const int sampled_rows = std::max(0, (a.rows - phase + stride - 1) / stride);
  std::vector<std::vector<std::int64_t>> by_row(static_cast<std::size_t>(sampled_rows));
  core::parallel_for_index(sampled_rows, settings.threads, [&](int k) {
    const int row = phase + k * stride;
    for (int col = phase; col < a.columns; col += stride) {
      const std::size_t i = a.index(row, col);
      if (scan.in_model[i] && usable_color(a, i, settings) &&
          locally_uniform(a, i, settings.max_local_step))
        by_row[static_cast<std::size_t>(k)].push_back(static_cast<std::int64_t>(i));
    }
  });
  ColorSamples out;
  for (const std::vector<std::int64_t>& row : by_row)
    out.pixels.insert(out.pixels.end(), row.begin(), row.end());
  out.points.reserve(out.size());
  out.normals.reserve(out.size());
  out.rgb.reserve(out.size());
  for (const std::int64_t pixel : out.pixels) {
    const auto i = static_cast<std::size_t>(pixel);
    out.points.push_back(scan.points[i]);
    out.normals.push_back(scan.geometry->normal[i]);
    out.rgb.push_back(linear_color(a, i));
  }
  return out;
}

std::vector<ColorPair> color_pairs_between(const ColorSamples& a, const PreparedScan& b,
                                           std::uint32_t ia, std::uint32_t ib,
                                           const Eigen::Isometry3d& T_world_a,
                                           const Eigen::Isometry3d& T_world_b,
                                           const ColorPairSettings& settings) {
  if (a.size() == 0 || !b.scan->has_color()) return {};
  const Eigen::Isometry3f T_b_a = (T_world_b.inverse() * T_world_a).cast<float>();
  std::vector<ColorPair> found = pairs_between(a, b, ia, ib, T_b_a, settings);
  const std::size_t limit = settings.max_pairs_per_overlap;
  if (limit > 0 && found.size() > limit) {
    std::vector<ColorPair> thinned;
    thinned.reserve(limit);
    for (std::size_t k = 0; k < limit; ++k) thinned.push_back(found[k * found.size() / limit]);
    found = std::move(thinned);
  }
  return found;
}

std::vector<ColorPair> find_color_pairs(std::span<const PreparedScan> scans,
                                        std::span<const Eigen::Isometry3d> T_world_scan,
                                        const ColorPairSettings& settings) {
  assert(scans.size() == T_world_scan.size() && "one pose per scan");
  std::vector<ColorPair> out;
  for (std::size_t a = 0; a < scans.size(); ++a) {
    const ColorSamples samples = color_samples(scans[a], settings);
    for (std::size_t b = a + 1; b < scans.size(); ++b) {
      const std::vector<ColorPair> found = color_pairs_between(
          samples, scans[b], static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
          T_world_scan[a], T_world_scan[b], settings);
      out.insert(out.end(), found.begin(), found.end());
    }
  }
  return out;
}

HarmonizeResult harmonize_colors(std::span<const ColorPair> pairs, std::size_t scan_count,
                                 const HarmonizeSettings& settings) {
  HarmonizeResult result;
  result.corrections.resize(scan_count);
  result.reference = group_references(pairs, scan_count);
  if (pairs.empty()) return result;
  std::vector<std::size_t> pairs_of(scan_count, 0);
  for (const ColorPair& pair : pairs) {
    ++pairs_of[pair.scan_a];
    ++pairs_of[pair.scan_b];
  }
  std::vector<std::uint8_t> solved(scan_count, 0);
  std::vector<double> prior_weight(scan_count, 0.0);
  for (std::size_t k = 0; k < scan_count; ++k) {
    solved[k] = result.reference[k] >= 0 && result.reference[k] != static_cast<std::int32_t>(k);
    prior_weight[k] = settings.prior_weight * std::sqrt(static_cast<double>(pairs_of[k]));
  }
  const ColorSolveOutcome solve = solve_color_parameters(pairs, solved, prior_weight, settings);
  result.pairs = pairs.size();
  result.initial_cost = solve.initial_cost;
  result.final_cost = solve.final_cost;
  result.iterations = solve.iterations;
  result.converged = solve.converged;
  for (std::size_t k = 0; k < scan_count; ++k) {
    if (solved[k]) result.corrections[k] = correction_of(solve.parameters[k], settings.model);
  }
  return result;
}

}  // namespace scanbench::registration

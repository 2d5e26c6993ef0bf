#include "registration/color_harmonization.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numeric>

#include "acquisition/color_space.hpp"
#include "core/parallel.hpp"

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
bool locally_uniform(const acquisition::Scan& scan, std::size_t i, int limit) {
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

// Pairs from a's sampled pixels into b, in a's row order.
std::vector<ColorPair> pairs_between(const PreparedScan& a, const PreparedScan& b, std::uint32_t ia,
                                     std::uint32_t ib, const Eigen::Isometry3f& T_b_a,
                                     const ColorPairSettings& s) {
  const acquisition::Scan& scan_a = *a.scan;
  const acquisition::Scan& scan_b = *b.scan;
  const double min_cos = std::cos(s.max_normal_angle_deg * 3.14159265358979323846 / 180.0);
  const int stride = std::max(1, s.stride);
  const int phase = std::clamp(s.phase, 0, stride - 1);
  const int sampled_rows = std::max(0, (scan_a.rows - phase + stride - 1) / stride);
  std::vector<std::vector<ColorPair>> by_row(static_cast<std::size_t>(sampled_rows));
  core::parallel_for_index(sampled_rows, s.threads, [&](int k) {
    const int row = phase + k * stride;
    for (int col = phase; col < scan_a.columns; col += stride) {
      const std::size_t i = scan_a.index(row, col);
      if (!a.in_model[i] || !usable_color(scan_a, i, s) ||
          !locally_uniform(scan_a, i, s.max_local_step))
        continue;
      const Eigen::Vector3f p = T_b_a * a.points[i];
      const std::int64_t found = associate(b, p);
      if (found < 0) continue;
      const auto j = static_cast<std::size_t>(found);
      if (!b.in_model[j] || !usable_color(scan_b, j, s) ||
          !locally_uniform(scan_b, j, s.max_local_step))
        continue;
      const double reach = s.max_distance_m + 2.0 * b.geometry->footprint_m[j];
      if ((p - b.points[j]).norm() > reach) continue;
      const Eigen::Vector3f& na = a.geometry->normal[i];
      const Eigen::Vector3f& nb = b.geometry->normal[j];
      if (na.squaredNorm() > 0.25f && nb.squaredNorm() > 0.25f &&
          (T_b_a.linear() * na).dot(nb) < min_cos)
        continue;
      by_row[static_cast<std::size_t>(k)].push_back(
          {ia, ib, static_cast<std::int64_t>(i), found, linear_color(scan_a, i),
           linear_color(scan_b, j)});
    }
  });
  std::vector<ColorPair> out;
  for (const std::vector<ColorPair>& row : by_row) out.insert(out.end(), row.begin(), row.end());
  return out;
}

// The corrected colour under a scan's parameters (gain-offset: g, o;
// matrix: M row-major, o).
template <ColorModel Model, typename T>
void correct(const T* p, const Eigen::Vector3f& rgb, T* out) {
  for (int c = 0; c < 3; ++c) {
    if constexpr (Model == ColorModel::kGainOffset) {
      out[c] = p[c] * T(rgb[c]) + p[3 + c];
    } else {
      out[c] = p[3 * c] * T(rgb[0]) + p[3 * c + 1] * T(rgb[1]) + p[3 * c + 2] * T(rgb[2]) +
               p[9 + c];
    }
  }
}

constexpr double kSoftLogEpsilon = 0.01;

template <ColorModel Model>
struct PairCost {
  Eigen::Vector3f a, b;
  template <typename T>
  bool operator()(const T* pa, const T* pb, T* residual) const {
    using std::log;
    T ca[3], cb[3];
    correct<Model>(pa, a, ca);
    correct<Model>(pb, b, cb);
    // A soft logarithm: relative differences for bright colours (a gain is
    // a shift there, so shrinking every colour towards one never pays),
    // absolute ones near black, where noise would dominate a true log.
    const T floor(0.0);
    const T soft(kSoftLogEpsilon);
    for (int c = 0; c < 3; ++c) {
      residual[c] = log((ca[c] < floor ? floor : ca[c]) + soft) -
                    log((cb[c] < floor ? floor : cb[c]) + soft);
    }
    return true;
  }
};

template <ColorModel Model>
ceres::CostFunction* pair_cost(const ColorPair& pair) {
  constexpr int kParameters = Model == ColorModel::kGainOffset ? 6 : 12;
  return new ceres::AutoDiffCostFunction<PairCost<Model>, 3, kParameters, kParameters>(
      new PairCost<Model>{pair.rgb_a, pair.rgb_b});
}

// Pulls a scan's parameters towards the identity, weighted by
// `weight`: without it, scans that no correction can make agree (sunlit in
// one, shaded in another) would collapse towards one flat colour, which
// agrees with itself and gives up only the pairs with the fixed scan.
struct IdentityPrior {
  std::vector<double> identity;
  double weight = 0.0;
  template <typename T>
  bool operator()(const T* const* parameters, T* residual) const {
    for (std::size_t k = 0; k < identity.size(); ++k)
      residual[k] = T(weight) * (parameters[0][k] - T(identity[k]));
    return true;
  }
};

// Which scans a chain of pairs links to scan 0.
std::vector<std::uint8_t> linked_to_first(std::span<const ColorPair> pairs, std::size_t count) {
  std::vector<std::size_t> root(count);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](std::size_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  for (const ColorPair& p : pairs) root[find(p.scan_a)] = find(p.scan_b);
  std::vector<std::uint8_t> out(count, 0);
  for (std::size_t k = 0; k < count; ++k) out[k] = count > 0 && find(k) == find(0) ? 1 : 0;
  return out;
}

}  // namespace

std::string_view color_model_name(ColorModel model) {
  return kModelNames[static_cast<std::size_t>(model)];
}

std::vector<ColorPair> find_color_pairs(std::span<const PreparedScan> scans,
                                        std::span<const Eigen::Isometry3d> T_world_scan,
                                        const ColorPairSettings& settings) {
  assert(scans.size() == T_world_scan.size() && "one pose per scan");
  std::vector<ColorPair> out;
  for (std::size_t a = 0; a < scans.size(); ++a) {
    for (std::size_t b = a + 1; b < scans.size(); ++b) {
      if (!scans[a].scan->has_color() || !scans[b].scan->has_color()) continue;
      const Eigen::Isometry3f T_b_a = (T_world_scan[b].inverse() * T_world_scan[a]).cast<float>();
      std::vector<ColorPair> found =
          pairs_between(scans[a], scans[b], static_cast<std::uint32_t>(a),
                        static_cast<std::uint32_t>(b), T_b_a, settings);
      const std::size_t limit = settings.max_pairs_per_overlap;
      if (limit > 0 && found.size() > limit) {
        std::vector<ColorPair> thinned;
        thinned.reserve(limit);
        for (std::size_t k = 0; k < limit; ++k) thinned.push_back(found[k * found.size() / limit]);
        found = std::move(thinned);
      }
      out.insert(out.end(), found.begin(), found.end());
    }
  }
  return out;
}

HarmonizeResult harmonize_colors(std::span<const ColorPair> pairs, std::size_t scan_count,
                                 const HarmonizeSettings& settings) {
  HarmonizeResult result;
  result.corrections.resize(scan_count);
  result.connected = linked_to_first(pairs, scan_count);
  if (scan_count < 2) return result;
  const bool matrix = settings.model == ColorModel::kMatrix;
  const std::size_t size = matrix ? 12 : 6;
  std::vector<std::vector<double>> parameters(scan_count, std::vector<double>(size, 0.0));
  for (std::vector<double>& p : parameters) {
    for (int c = 0; c < 3; ++c) p[static_cast<std::size_t>(matrix ? 4 * c : c)] = 1.0;
  }
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(settings.loss_scale);
  for (const ColorPair& pair : pairs) {
    if (!result.connected[pair.scan_a]) continue;  // both or neither: a pair links them
    problem.AddResidualBlock(
        matrix ? pair_cost<ColorModel::kMatrix>(pair) : pair_cost<ColorModel::kGainOffset>(pair),
        &loss, parameters[pair.scan_a].data(), parameters[pair.scan_b].data());
    ++result.pairs;
  }
  if (result.pairs == 0) return result;
  problem.SetParameterBlockConstant(parameters[0].data());
  std::vector<std::size_t> pairs_of(scan_count, 0);
  for (const ColorPair& pair : pairs) {
    if (!result.connected[pair.scan_a]) continue;
    ++pairs_of[pair.scan_a];
    ++pairs_of[pair.scan_b];
  }
  const std::vector<double> identity = parameters[0];
  for (std::size_t k = 1; k < scan_count; ++k) {
    if (pairs_of[k] == 0) continue;
    auto* prior = new ceres::DynamicAutoDiffCostFunction<IdentityPrior>(new IdentityPrior{
        identity, settings.prior_weight * std::sqrt(static_cast<double>(pairs_of[k]))});
    prior->AddParameterBlock(static_cast<int>(size));
    prior->SetNumResiduals(static_cast<int>(size));
    problem.AddResidualBlock(prior, nullptr, parameters[k].data());
  }
  // Bounds of what exposure, white balance and flare can do: gains within
  // max_gain_ratio either way, channel cross-talk and offsets small. They
  // also keep scans that cannot agree from collapsing to one flat colour.
  for (std::size_t k = 1; k < scan_count; ++k) {
    if (pairs_of[k] == 0) continue;
    double* p = parameters[k].data();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < (matrix ? 3 : 1); ++c) {
        const int at = matrix ? 3 * r + c : r;
        const bool diagonal = !matrix || r == c;
        problem.SetParameterLowerBound(p, at, diagonal ? 1.0 / settings.max_gain_ratio
                                                       : -settings.max_cross_talk);
        problem.SetParameterUpperBound(p, at, diagonal ? settings.max_gain_ratio
                                                       : settings.max_cross_talk);
      }
      const int offset = (matrix ? 9 : 3) + r;
      problem.SetParameterLowerBound(p, offset, -settings.max_offset);
      problem.SetParameterUpperBound(p, offset, settings.max_offset);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  options.max_num_iterations = settings.max_iterations;
  options.num_threads = core::worker_count(settings.threads);
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  for (std::size_t k = 1; k < scan_count; ++k) {
    if (!result.connected[k]) continue;
    const std::vector<double>& p = parameters[k];
    ColorCorrection& c = result.corrections[k];
    for (int r = 0; r < 3; ++r) {
      const auto ur = static_cast<std::size_t>(r);
      if (matrix) {
        for (int col = 0; col < 3; ++col) c.matrix(r, col) = p[3 * ur + static_cast<std::size_t>(col)];
        c.offset[r] = p[9 + ur];
      } else {
        c.matrix(r, r) = p[ur];
        c.offset[r] = p[3 + ur];
      }
    }
  }
  return result;
}

}  // namespace scanbench::registration

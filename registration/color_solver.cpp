// Levenberg–Marquardt with the damping update of Nielsen (Madsen, Nielsen
// and Tingleff, "Methods for non-linear least squares problems", 2004,
// §3.2), as Ceres' trust-region strategy does it, and bounds by projected
// Newton (Bertsekas 1982): a parameter at a bound that the gradient pushes
// against is held for the step, the others move and are clamped.
#include "registration/color_solver.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <utility>

#include "core/parallel.hpp"
#include "registration/color_costs.hpp"

namespace scanbench::registration {

namespace {

// Stopping and damping as the defaults of Ceres' Levenberg–Marquardt, which
// this solve replaced (without its Jacobi scaling): the relative cost change
// of an accepted step, the projected gradient, the relative step, the least
// useful step, the range of the damped diagonal, and the damping at the
// start and its range (the inverse of the trust region's radius: at most
// 1e16, at least 1e-32, where the solve stops as converged).
constexpr double kFunctionTolerance = 1e-6;
constexpr double kGradientTolerance = 1e-10;
constexpr double kParameterTolerance = 1e-8;
constexpr double kMinRelativeDecrease = 1e-3;
constexpr double kMinDiagonal = 1e-6;
constexpr double kMaxDiagonal = 1e32;
constexpr double kInitialDamping = 1e-4;
constexpr double kMinDamping = 1e-16;
constexpr double kMaxDamping = 1e32;

// A pair of scans that share pairs: theirs are order[begin, end).
struct Link {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  std::size_t begin = 0;
  std::size_t end = 0;
};

struct LinkOrder {
  std::vector<std::uint32_t> order;  // pair indices, by (scan_a, scan_b), stable
  std::vector<Link> links;
};

LinkOrder links_of(std::span<const ColorPair> pairs) {
  LinkOrder out;
  out.order.resize(pairs.size());
  std::iota(out.order.begin(), out.order.end(), 0U);
  std::stable_sort(out.order.begin(), out.order.end(), [&](std::uint32_t i, std::uint32_t j) {
    return std::pair(pairs[i].scan_a, pairs[i].scan_b) <
           std::pair(pairs[j].scan_a, pairs[j].scan_b);
  });
  for (std::size_t k = 0; k < out.order.size(); ++k) {
    const ColorPair& p = pairs[out.order[k]];
    if (out.links.empty() || out.links.back().a != p.scan_a || out.links.back().b != p.scan_b)
      out.links.push_back({p.scan_a, p.scan_b, k, k});
    out.links.back().end = k + 1;
  }
  return out;
}

// Lower and upper bound of each parameter: gains within max_gain_ratio
// either way, channel cross-talk and offsets small.
std::pair<std::vector<double>, std::vector<double>> parameter_bounds(
    ColorModel model, const HarmonizeSettings& settings) {
  const auto count = static_cast<std::size_t>(costs::color_parameter_count(model));
  std::vector<double> lower(count), upper(count);
  const auto bound = [&](int i, double low, double high) {
    lower[static_cast<std::size_t>(i)] = low;
    upper[static_cast<std::size_t>(i)] = high;
  };
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      const int i = costs::matrix_parameter(model, row, col);
      if (i < 0) continue;
      if (row == col)
        bound(i, 1.0 / settings.max_gain_ratio, settings.max_gain_ratio);
      else
        bound(i, -settings.max_cross_talk, settings.max_cross_talk);
    }
    bound(costs::offset_parameter(model, row), -settings.max_offset, settings.max_offset);
  }
  return {lower, upper};
}

// Levenberg–Marquardt over the normal equations of the links.
template <ColorModel Model>
class LinkSolver {
 public:
  static constexpr int P = costs::kColorParameters<Model>;
  using Block = Eigen::Matrix<double, P, P>;
  using Vector = Eigen::Matrix<double, P, 1>;

  LinkSolver(std::span<const ColorPair> pairs, std::span<const std::uint8_t> solved,
             std::span<const double> prior_weight, const HarmonizeSettings& settings)
      : pairs_(pairs),
        prior_weight_(prior_weight),
        settings_(settings),
        links_(links_of(pairs)),
        identity_(identity_color_parameters(Model)),
        bounds_(parameter_bounds(Model, settings)),
        column_(solved.size(), -1) {
    for (std::size_t k = 0; k < solved.size(); ++k) {
      if (solved[k]) column_[k] = static_cast<int>(P * unknowns_++);
    }
  }

  ColorSolveOutcome run() {
    std::vector<double> x(column_.size() * P);
    for (std::size_t k = 0; k < column_.size(); ++k)
      std::copy(identity_.begin(), identity_.end(), x.begin() + static_cast<long>(k * P));
    ColorSolveOutcome out;
    System system = linearize(x);
    out.initial_cost = system.cost;
    if (unknowns_ > 0) iterate(x, system, out);
    out.final_cost = system.cost;
    out.parameters.resize(column_.size());
    for (std::size_t k = 0; k < column_.size(); ++k)
      out.parameters[k].assign(x.begin() + static_cast<long>(k * P),
                               x.begin() + static_cast<long>((k + 1) * P));
    return out;
  }

 private:
  // The normal equations at some parameters: H = Σ w JᵀJ + priors,
  // g = Σ w Jᵀr + priors, over the solved scans' columns, and the cost.
  struct System {
    Eigen::SparseMatrix<double> H;
    Eigen::VectorXd g;
    double cost = 0.0;
  };

  // What one link's pairs add: the blocks of both scans and between them.
  struct LinkTerms {
    Block aa = Block::Zero(), ab = Block::Zero(), bb = Block::Zero();
    Vector ga = Vector::Zero(), gb = Vector::Zero();
    double cost = 0.0;
  };

  LinkTerms link_terms(const Link& link, const std::vector<double>& x) const {
    LinkTerms t;
    const double* pa = x.data() + std::size_t{link.a} * P;
    const double* pb = x.data() + std::size_t{link.b} * P;
    costs::PairJacobian<Model> Ja, Jb;
    for (std::size_t k = link.begin; k < link.end; ++k) {
      const ColorPair& pair = pairs_[links_.order[k]];
      const Eigen::Vector3d r =
          costs::pair_residual<Model>(pa, pb, pair.rgb_a, pair.rgb_b, &Ja, &Jb);
      const double s = r.squaredNorm();
      t.cost += 0.5 * costs::cauchy_loss(s, settings_.loss_scale);
      const double w = costs::cauchy_weight(s, settings_.loss_scale);
      t.aa.noalias() += w * Ja.transpose() * Ja;
      t.ab.noalias() += w * Ja.transpose() * Jb;
      t.bb.noalias() += w * Jb.transpose() * Jb;
      t.ga.noalias() += w * Ja.transpose() * r;
      t.gb.noalias() += w * Jb.transpose() * r;
    }
    return t;
  }

  // Links on the workers, summed in link order: the same for any thread
  // count.
  System linearize(const std::vector<double>& x) const {
    std::vector<LinkTerms> terms(links_.links.size());
    core::parallel_for_index(static_cast<int>(terms.size()), settings_.threads, [&](int l) {
      terms[static_cast<std::size_t>(l)] = link_terms(links_.links[static_cast<std::size_t>(l)], x);
    });
    System system;
    system.g = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(unknowns_ * P));
    std::vector<Eigen::Triplet<double>> entries;
    const auto add_block = [&](int row, int col, const Block& block) {
      if (row < 0 || col < 0) return;
      for (int i = 0; i < P; ++i)
        for (int j = 0; j < P; ++j) entries.emplace_back(row + i, col + j, block(i, j));
    };
    for (std::size_t l = 0; l < terms.size(); ++l) {
      const LinkTerms& t = terms[l];
      const int ca = column_[links_.links[l].a], cb = column_[links_.links[l].b];
      add_block(ca, ca, t.aa);
      add_block(cb, cb, t.bb);
      add_block(ca, cb, t.ab);
      add_block(cb, ca, t.ab.transpose());
      if (ca >= 0) system.g.template segment<P>(ca) += t.ga;
      if (cb >= 0) system.g.template segment<P>(cb) += t.gb;
      system.cost += t.cost;
    }
    for (std::size_t k = 0; k < column_.size(); ++k) {
      const int c = column_[k];
      if (c < 0) continue;
      const double w2 = prior_weight_[k] * prior_weight_[k];
      const Vector d =
          Eigen::Map<const Vector>(x.data() + k * P) - Eigen::Map<const Vector>(identity_.data());
      add_block(c, c, w2 * Block::Identity());
      system.g.template segment<P>(c) += w2 * d;
      system.cost += 0.5 * w2 * d.squaredNorm();
    }
    const auto n = static_cast<Eigen::Index>(unknowns_ * P);
    system.H.resize(n, n);
    system.H.setFromTriplets(entries.begin(), entries.end());
    return system;
  }

  // Calls f(at, column, i) for parameter i of every solved scan: `at` its
  // place in x, `column` its place in the system.
  template <typename F>
  void for_each_solved(F&& f) const {
    for (std::size_t k = 0; k < column_.size(); ++k) {
      if (column_[k] < 0) continue;
      for (int i = 0; i < P; ++i)
        f(k * P + static_cast<std::size_t>(i), column_[k] + i, static_cast<std::size_t>(i));
    }
  }

  // The solved parameters of x moved by `step` and held within bounds.
  std::vector<double> moved(const std::vector<double>& x, const Eigen::VectorXd& step) const {
    std::vector<double> out = x;
    for_each_solved([&](std::size_t at, int column, std::size_t i) {
      out[at] = std::clamp(out[at] + step[column], bounds_.first[i], bounds_.second[i]);
    });
    return out;
  }

  // The solved columns of b − a.
  Eigen::VectorXd difference(const std::vector<double>& a, const std::vector<double>& b) const {
    Eigen::VectorXd d(static_cast<Eigen::Index>(unknowns_ * P));
    for_each_solved([&](std::size_t at, int column, std::size_t) { d[column] = b[at] - a[at]; });
    return d;
  }

  // The largest move of a projected gradient step: zero at a bounded
  // stationary point.
  double projected_gradient(const std::vector<double>& x, const Eigen::VectorXd& g) const {
    return difference(x, moved(x, -g)).cwiseAbs().maxCoeff();
  }

  // Per column, whether its parameter sits at a bound that the gradient
  // pushes it against: the step leaves it there (projected Newton), so
  // that clamping the step does not turn it uphill.
  std::vector<std::uint8_t> held_at_bounds(const std::vector<double>& x,
                                           const Eigen::VectorXd& g) const {
    std::vector<std::uint8_t> held(static_cast<std::size_t>(g.size()), 0);
    for_each_solved([&](std::size_t at, int column, std::size_t i) {
      const double slope = g[column];
      held[static_cast<std::size_t>(column)] =
          (x[at] <= bounds_.first[i] && slope > 0.0) || (x[at] >= bounds_.second[i] && slope < 0.0);
    });
    return held;
  }

  // H with its diagonal raised by `damping` times itself (within
  // [kMinDiagonal, kMaxDiagonal]), and the rows and columns of held
  // parameters replaced by the identity's.
  static Eigen::SparseMatrix<double> damped_matrix(const Eigen::SparseMatrix<double>& H,
                                                   double damping,
                                                   const std::vector<std::uint8_t>& held) {
    Eigen::SparseMatrix<double> out = H;
    for (Eigen::Index col = 0; col < out.outerSize(); ++col) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(out, col); it; ++it) {
        const bool row_held = held[static_cast<std::size_t>(it.row())] != 0;
        const bool col_held = held[static_cast<std::size_t>(col)] != 0;
        if (it.row() == col) {
          it.valueRef() =
              row_held ? 1.0
                       : it.value() + damping * std::clamp(it.value(), kMinDiagonal, kMaxDiagonal);
        } else if (row_held || col_held) {
          it.valueRef() = 0.0;
        }
      }
    }
    return out;
  }

  void iterate(std::vector<double>& x, System& system, ColorSolveOutcome& out) const {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> cholesky;
    cholesky.analyzePattern(system.H);
    double damping = kInitialDamping, growth = 2.0;
    const auto reject = [&] {
      damping *= growth;
      growth *= 2.0;
    };
    while (out.iterations < settings_.max_iterations) {
      if (damping >= kMaxDamping || projected_gradient(x, system.g) <= kGradientTolerance) {
        out.converged = true;
        return;
      }
      ++out.iterations;
      const std::vector<std::uint8_t> held = held_at_bounds(x, system.g);
      cholesky.factorize(damped_matrix(system.H, damping, held));
      if (cholesky.info() != Eigen::Success) {
        reject();
        continue;
      }
      Eigen::VectorXd rhs = -system.g;
      for (Eigen::Index i = 0; i < rhs.size(); ++i)
        if (held[static_cast<std::size_t>(i)]) rhs[i] = 0.0;
      const std::vector<double> candidate = moved(x, cholesky.solve(rhs));
      const Eigen::VectorXd step = difference(x, candidate);
      const double size =
          Eigen::Map<const Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size())).norm();
      if (step.norm() <= kParameterTolerance * (size + kParameterTolerance)) {
        out.converged = true;
        return;
      }
      const double predicted = -(system.g.dot(step) + 0.5 * step.dot(system.H * step));
      System next = linearize(candidate);
      const double decrease = system.cost - next.cost;
      const double quality = predicted > 0.0 ? decrease / predicted : -1.0;
      if (quality < kMinRelativeDecrease) {
        reject();
        continue;
      }
      const bool settled = decrease <= kFunctionTolerance * system.cost;
      x = candidate;
      system = std::move(next);
      damping = std::max(kMinDamping,
                         damping * std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3)));
      growth = 2.0;
      if (settled) {
        out.converged = true;
        return;
      }
    }
  }

  std::span<const ColorPair> pairs_;
  std::span<const double> prior_weight_;
  const HarmonizeSettings& settings_;
  LinkOrder links_;
  std::vector<double> identity_;
  std::pair<std::vector<double>, std::vector<double>> bounds_;
  std::vector<int> column_;   // per scan: its first column, or −1 if not solved
  std::size_t unknowns_ = 0;  // solved scans
};

}  // namespace

std::vector<double> identity_color_parameters(ColorModel model) {
  std::vector<double> p(static_cast<std::size_t>(costs::color_parameter_count(model)), 0.0);
  for (int c = 0; c < 3; ++c)
    p[static_cast<std::size_t>(costs::matrix_parameter(model, c, c))] = 1.0;
  return p;
}

ColorSolveOutcome solve_color_parameters(std::span<const ColorPair> pairs,
                                         std::span<const std::uint8_t> solved,
                                         std::span<const double> prior_weight,
                                         const HarmonizeSettings& settings) {
  assert(solved.size() == prior_weight.size() && "one flag and one prior weight a scan");
  assert(settings.max_gain_ratio >= 1.0 && settings.max_offset >= 0.0 &&
         settings.max_cross_talk >= 0.0 && "bounds that contain the identity");
  assert(std::all_of(pairs.begin(), pairs.end(),
                     [&](const ColorPair& p) {
                       return p.scan_a < solved.size() && p.scan_b < solved.size();
                     }) &&
         "every pair's scans have a flag");
  if (settings.model == ColorModel::kMatrix)
    return LinkSolver<ColorModel::kMatrix>(pairs, solved, prior_weight, settings).run();
  return LinkSolver<ColorModel::kGainOffset>(pairs, solved, prior_weight, settings).run();
}

}  // namespace scanbench::registration

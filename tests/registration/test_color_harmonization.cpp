// The colour harmonisation solver on synthetic pairs: known gains and
// offsets come back with outliers among the pairs, the first scan of each
// group of overlapping scans stays fixed, a scan in no pair is left alone,
// the solve is deterministic and keeps its bounds, and the costs'
// derivatives are right. And the samples a scan gives the pair search, on a hand-made grid.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "acquisition/color_space.hpp"
#include "registration/color_costs.hpp"
#include "registration/color_harmonization.hpp"
#include "registration/color_solver.hpp"

namespace scanbench::registration {
namespace {

struct Truth {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
};

// Pairs among `truth.size()` scans (each scan's colour is truth⁻¹ of the
// surface's, so the correction `truth` brings it back), a share of them
// outliers (unrelated colours: a shadow in one scan, a wrong match).
std::vector<ColorPair> synthetic_pairs(const std::vector<Truth>& truth, double outliers,
                                       std::uint32_t skip_scan = 99) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(0.03, 0.7);
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  std::vector<ColorPair> pairs;
  for (std::uint32_t a = 0; a < truth.size(); ++a) {
    for (std::uint32_t b = a + 1; b < truth.size(); ++b) {
      if (a == skip_scan || b == skip_scan) continue;
      for (int k = 0; k < 3000; ++k) {
        const Eigen::Vector3d surface(unit(random), unit(random), unit(random));
        const auto seen = [&](std::uint32_t s) {
          return Eigen::Vector3d(truth[s].matrix.inverse() * (surface - truth[s].offset))
              .cast<float>()
              .eval();
        };
        ColorPair pair{a, b, 0, 0, seen(a), seen(b)};
        if (coin(random) < outliers)
          pair.rgb_b = Eigen::Vector3d(unit(random), unit(random), unit(random)).cast<float>();
        pairs.push_back(pair);
      }
    }
  }
  return pairs;
}

TEST(ColorHarmonization, GainsAndOffsetsComeBackDespiteOutliers) {
  std::vector<Truth> truth(3);
  truth[1].matrix.diagonal() << 1.3, 0.85, 1.1;
  truth[1].offset << 0.004, -0.002, 0.0;
  truth[2].matrix.diagonal() << 0.7, 0.75, 0.9;
  const std::vector<ColorPair> pairs = synthetic_pairs(truth, 0.2);
  const HarmonizeResult out = harmonize_colors(pairs, 3, {});
  EXPECT_EQ(out.pairs, pairs.size());
  EXPECT_TRUE(out.corrections[0].matrix.isIdentity());
  for (std::size_t s = 1; s < 3; ++s) {
    EXPECT_EQ(out.reference[s], 0);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(out.corrections[s].matrix(c, c), truth[s].matrix(c, c), 0.01) << s << "," << c;
      EXPECT_NEAR(out.corrections[s].offset[c], truth[s].offset[c], 0.002) << s << "," << c;
    }
  }
}

TEST(ColorHarmonization, TheMatrixModelFindsCrossTalk) {
  std::vector<Truth> truth(2);
  truth[1].matrix << 1.1, 0.05, 0.0,  //
      0.0, 0.95, 0.04,                //
      -0.03, 0.0, 1.2;
  const std::vector<ColorPair> pairs = synthetic_pairs(truth, 0.1);
  HarmonizeSettings settings;
  settings.model = ColorModel::kMatrix;
  const HarmonizeResult out = harmonize_colors(pairs, 2, settings);
  EXPECT_LT((out.corrections[1].matrix - truth[1].matrix).cwiseAbs().maxCoeff(), 0.01)
      << out.corrections[1].matrix;
  EXPECT_LT(out.corrections[1].offset.cwiseAbs().maxCoeff(), 0.002);
}

TEST(ColorHarmonization, AScanWithoutOverlapsIsLeftAlone) {
  std::vector<Truth> truth(3);
  truth[1].matrix.diagonal() << 1.2, 1.2, 1.2;
  truth[2].matrix.diagonal() << 0.5, 0.5, 0.5;
  const HarmonizeResult out = harmonize_colors(synthetic_pairs(truth, 0.0, 2), 3, {});
  EXPECT_EQ(out.reference[1], 0);
  EXPECT_EQ(out.reference[2], -1);
  EXPECT_TRUE(out.corrections[2].matrix.isIdentity());
  EXPECT_NEAR(out.corrections[1].matrix(0, 0), 1.2, 0.005);
  EXPECT_TRUE(harmonize_colors({}, 1, {}).corrections[0].matrix.isIdentity());
}

// Scans 1 and 2 overlap each other but not scan 0 (which may have no
// colour): scan 1 is their reference, and scan 2 is brought to it.
TEST(ColorHarmonization, EachGroupOfOverlappingScansHasItsOwnReference) {
  std::vector<Truth> truth(3);
  truth[2].matrix.diagonal() << 1.3, 1.1, 0.9;
  std::vector<ColorPair> pairs = synthetic_pairs(truth, 0.0, 0);
  const HarmonizeResult out = harmonize_colors(pairs, 3, {});
  EXPECT_EQ(out.reference[0], -1);
  EXPECT_EQ(out.reference[1], 1);
  EXPECT_EQ(out.reference[2], 1);
  EXPECT_TRUE(out.corrections[1].matrix.isIdentity());
  EXPECT_NEAR(out.corrections[2].matrix(0, 0), 1.3, 0.005);
  EXPECT_NEAR(out.corrections[2].matrix(2, 2), 0.9, 0.005);
}

// The solve sums each link's pairs in their order and the links in scan
// order: the same bits on one worker or two, and whatever the order of the
// links among the pairs.
TEST(ColorHarmonization, TheSolveIsTheSameForAnyThreadCountAndLinkOrder) {
  std::vector<Truth> truth(4);
  truth[1].matrix.diagonal() << 1.3, 0.85, 1.1;
  truth[2].matrix.diagonal() << 0.7, 0.75, 0.9;
  truth[3].offset << 0.003, 0.0, -0.001;
  const std::vector<ColorPair> pairs = synthetic_pairs(truth, 0.2);
  std::vector<ColorPair> by_link_backwards;
  for (std::size_t end = pairs.size(); end > 0; end -= 3000)
    by_link_backwards.insert(by_link_backwards.end(), pairs.begin() + static_cast<long>(end - 3000),
                             pairs.begin() + static_cast<long>(end));
  HarmonizeSettings one;
  one.threads = 1;
  HarmonizeSettings two;
  two.threads = 2;
  const HarmonizeResult first = harmonize_colors(pairs, 4, one);
  for (const HarmonizeResult& other :
       {harmonize_colors(pairs, 4, two), harmonize_colors(by_link_backwards, 4, two)}) {
    EXPECT_EQ(other.final_cost, first.final_cost);
    EXPECT_EQ(other.iterations, first.iterations);
    for (std::size_t s = 0; s < 4; ++s) {
      EXPECT_EQ(other.corrections[s].matrix, first.corrections[s].matrix) << s;
      EXPECT_EQ(other.corrections[s].offset, first.corrections[s].offset) << s;
    }
  }
}

// A scan two and a half times too dark with gains bounded at 2: the solve
// stops at the bound, where the bounded problem is stationary.
TEST(ColorHarmonization, AGainBeyondItsBoundStopsAtTheBound) {
  std::vector<Truth> truth(2);
  truth[1].matrix.diagonal() << 2.5, 2.5, 1.5;
  HarmonizeSettings settings;
  settings.max_gain_ratio = 2.0;
  const HarmonizeResult out = harmonize_colors(synthetic_pairs(truth, 0.0), 2, settings);
  EXPECT_TRUE(out.converged);
  EXPECT_EQ(out.corrections[1].matrix(0, 0), 2.0);
  EXPECT_EQ(out.corrections[1].matrix(1, 1), 2.0);
  EXPECT_LT(out.corrections[1].matrix(2, 2), 2.0);
  EXPECT_LT(out.final_cost, out.initial_cost);
}

// The derivatives of color_costs.hpp against central differences, for both
// models, at parameters away from the identity.
template <ColorModel Model>
void expect_jacobians_match_differences() {
  constexpr int P = costs::kColorParameters<Model>;
  std::vector<double> pa = identity_color_parameters(Model), pb = pa;
  for (int i = 0; i < P; ++i) {
    pa[static_cast<std::size_t>(i)] += 0.05 * std::sin(1.0 + i);
    pb[static_cast<std::size_t>(i)] += 0.04 * std::cos(2.0 + i);
  }
  const Eigen::Vector3f rgb_a(0.2f, 0.45f, 0.08f), rgb_b(0.3f, 0.1f, 0.6f);
  costs::PairJacobian<Model> Ja, Jb;
  costs::pair_residual<Model>(pa.data(), pb.data(), rgb_a, rgb_b, &Ja, &Jb);
  constexpr double h = 1e-6;
  for (int i = 0; i < P; ++i) {
    for (std::vector<double>* p : {&pa, &pb}) {
      std::vector<double> up = *p, down = *p;
      up[static_cast<std::size_t>(i)] += h;
      down[static_cast<std::size_t>(i)] -= h;
      const bool a = p == &pa;
      const Eigen::Vector3d difference =
          (costs::pair_residual<Model>(a ? up.data() : pa.data(), a ? pb.data() : up.data(), rgb_a,
                                       rgb_b) -
           costs::pair_residual<Model>(a ? down.data() : pa.data(), a ? pb.data() : down.data(),
                                       rgb_a, rgb_b)) /
          (2.0 * h);
      const Eigen::Vector3d analytic = a ? Ja.col(i) : Jb.col(i);
      EXPECT_LT((difference - analytic).cwiseAbs().maxCoeff(), 1e-6)
          << (a ? "a" : "b") << " parameter " << i;
    }
  }
}

TEST(ColorHarmonization, TheCostsDerivativesMatchDifferences) {
  expect_jacobians_match_differences<ColorModel::kGainOffset>();
  expect_jacobians_match_differences<ColorModel::kMatrix>();
}

// An 8 × 8 spherical grid of a wall 5 m away, grey 100 but for a dark pixel
// at (2, 2) and a bright one at (4, 4) that steps away from its neighbours.
struct GreyWall {
  acquisition::Scan scan = acquisition::make_empty_scan(8, 8, false, true);
  acquisition::ScanGeometry geometry;
  GreyWall() {
    const double step = 0.01;
    scan.angles = acquisition::SphericalAngles{0.04, -step, 0.04, -step};
    const std::size_t n = scan.pixel_count();
    geometry.footprint_m.assign(n, 0.05f);
    geometry.normal.assign(n, Eigen::Vector3f(-1.0f, 0.0f, 0.0f));
    geometry.confidence.assign(n, 1.0f);
    geometry.flags.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      scan.valid[i] = 1;
      scan.range_m[i] = 5.0f;
      for (std::size_t c = 0; c < 3; ++c) scan.rgb[3 * i + c] = 100;
    }
    for (std::size_t c = 0; c < 3; ++c) {
      scan.rgb[3 * scan.index(2, 2) + c] = 2;
      scan.rgb[3 * scan.index(4, 4) + c] = 200;
    }
  }
};

TEST(ColorSamples, TheSampledPixelsOfUsableUniformColourInRowOrder) {
  const GreyWall wall;
  const PreparedScan prepared = prepare_scan(wall.scan, wall.geometry, 1);
  ColorPairSettings settings;  // stride 2
  const ColorSamples even = color_samples(prepared, settings);
  std::vector<std::int64_t> expected;
  for (int row = 0; row < 8; row += 2)
    for (int col = 0; col < 8; col += 2)
      if (!(row == col && (row == 2 || row == 4)))  // dark; not uniform
        expected.push_back(static_cast<std::int64_t>(wall.scan.index(row, col)));
  EXPECT_EQ(even.pixels, expected);
  ASSERT_EQ(even.points.size(), expected.size());
  ASSERT_EQ(even.normals.size(), expected.size());
  ASSERT_EQ(even.rgb.size(), expected.size());
  const float grey = acquisition::srgb_to_linear(100);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    const auto i = static_cast<std::size_t>(expected[k]);
    EXPECT_EQ(even.points[k], prepared.points[i]);
    EXPECT_EQ(even.normals[k], wall.geometry.normal[i]);
    EXPECT_EQ(even.rgb[k], Eigen::Vector3f::Constant(grey));
  }
  // The odd pixels: none is dark, and the step at (4, 4) is not theirs.
  settings.phase = 1;
  EXPECT_EQ(color_samples(prepared, settings).size(), 16u);
  // Every pixel: the dark and the bright one go, and so do their four
  // neighbours each, which see their step.
  settings.stride = 1;
  settings.phase = 0;
  EXPECT_EQ(color_samples(prepared, settings).size(), 64u - 2u * (1u + 4u));
}

TEST(ColorSamples, AScanWithoutColourHasNone) {
  GreyWall wall;
  wall.scan.rgb.clear();
  const PreparedScan prepared = prepare_scan(wall.scan, wall.geometry, 1);
  EXPECT_EQ(color_samples(prepared, {}).size(), 0u);
}

}  // namespace
}  // namespace scanbench::registration

// The solve of colour harmonisation (color_harmonization.hpp): bounded
// Levenberg–Marquardt on the pair costs of color_costs.hpp under a Cauchy
// loss, with a pull of each solved scan towards the identity.
//
// Its normal equations are summed pair by pair, with each pair's weight
// from the loss at the current parameters (iteratively reweighted), into
// one block of P × P numbers per solved scan and one per linked pair of
// scans (P = 6 or 12 parameters). It holds the pairs and those blocks, not
// a row of Jacobian for every pair: its memory grows with the links of the
// overlap graph, and each iteration is one pass over the pairs.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "registration/color_harmonization.hpp"

namespace scanbench::registration {

struct ColorSolveOutcome {
  std::vector<std::vector<double>> parameters;  // per scan, color_costs.hpp's layout
  double initial_cost = 0.0;  // ½ Σ ρ(|r|²) + ½ Σ |prior|², at the identity
  double final_cost = 0.0;
  int iterations = 0;  // steps tried (linear systems solved), accepted or not
  bool converged = false;
};

// The identity correction's parameters under `model`.
std::vector<double> identity_color_parameters(ColorModel model);

// Solves the parameters of the scans whose `solved` flag is set; the others
// stay at the identity (each group's fixed scan, scans in no pair).
// `prior_weight[k]` weighs scan k's pull towards the identity. Every pair's
// scans index `solved` and `prior_weight`, which have one entry a scan
// (asserted), and the bounds contain the identity (asserted). Within
// HarmonizeSettings' bounds. Converged when an accepted step changes the
// cost by less than a millionth, the projected gradient vanishes, a step
// moves the parameters by less than 1e-8 of their norm, or no step is
// accepted even at the largest damping; not converged after
// settings.max_iterations steps. The same for any thread count.
ColorSolveOutcome solve_color_parameters(std::span<const ColorPair> pairs,
                                         std::span<const std::uint8_t> solved,
                                         std::span<const double> prior_weight,
                                         const HarmonizeSettings& settings);

}  // namespace scanbench::registration

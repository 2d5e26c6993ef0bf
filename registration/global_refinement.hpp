// Global refinement: all scan poses adjusted together over the pose graph of
// the measured pairs (the edges the registration chose), first scan held
// fixed, so that registration errors spread over a loop instead of
// accumulating along a chain of pairwise alignments.
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "registration/edge_targets.hpp"
#include "registration/icp.hpp"
#include "registration/sample_shelf.hpp"
#include "registration/scan_stream.hpp"

namespace scanbench::registration {

struct GlobalSettings {
  // Association is redone this many times at most; each round solves the
  // pose graph of the edges' Gauss-Newton quadratics, built at the round's
  // correspondences and poses (robust weights frozen for the round).
  int max_rounds = 10;
  // Levenberg-Marquardt steps of Ceres per round.
  int solver_iterations = 5;
  // Source samples per scan (thinned evenly) of the rounds until the poses
  // stop moving; the one polishing round after them uses every sample.
  std::size_t max_samples = 10000;
  // Gate of the first round [m] (the pairwise results are already close).
  double initial_gate_m = 0.1;
  // Gates, normal test, loss, stop thresholds and threads as in ICP.
  IcpSettings icp;
};

struct GlobalResult {
  // Pose of every scan in the first scan's frame; [0] is the identity.
  std::vector<Eigen::Isometry3d> T_first_scan;
  // A round on the thinned samples moved no pose beyond the ICP stop
  // thresholds (the polishing round on all samples follows it).
  bool converged = false;
  int rounds = 0;
  std::size_t correspondences = 0;  // over all edges, last round
  double seconds = 0.0;
};

// Refines `T_first_scan` (poses of all scans in the first scan's frame;
// [0] must be the identity, asserted) over `edges`. The cloud of slot i of
// `samples` (every slot put) and scan i of `scans` belong to scan i; each
// round visits every edge's target through `patches` (the edge's patch
// where it holds the round's pixels, else the target scan from the
// stream, after which the patch is made anew at the round's pose), and
// takes the samples of its source from the shelf. Edges with too few
// correspondences in a round add nothing to it.
GlobalResult refine_globally(SampleShelf& samples, ScanStream& scans, EdgePatches& patches,
                             std::vector<Eigen::Isometry3d> T_first_scan,
                             std::span<const ScanEdge> edges, const GlobalSettings& settings);

}  // namespace scanbench::registration

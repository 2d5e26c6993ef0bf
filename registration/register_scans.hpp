// The registration pipeline: coarse alignment of each scan to the one before
// it (picked point pairs, or features), point-to-plane ICP on that pair, and
// a global refinement over every overlapping pair with the first scan fixed.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/progress.hpp"
#include "registration/feature_alignment.hpp"
#include "registration/global_refinement.hpp"
#include "registration/icp.hpp"
#include "registration/prepared_scan.hpp"
#include "registration/rigid_fit.hpp"
#include "registration/scan_stream.hpp"

namespace scanbench::registration {

enum class CoarseMethod {
  kNone,        // start ICP from the initial poses
  kPointPairs,  // closed-form fit of user-picked point pairs
  kFeatures,    // FPFH + RANSAC, verified by ICP; ICP also tries the initial pose, the better wins
};

// Where the fine stage of a pair started.
enum class IcpStart {
  kInitial,  // the source's initial pose against the target's registered pose
  kCoarse,   // the coarse stage's pose
};

// "none", "point_pairs", "features": the names in reports and settings.
const char* coarse_method_name(CoarseMethod method);
// The method coarse_method_name names, or none for any other text.
std::optional<CoarseMethod> coarse_method_from_name(std::string_view name);
// "initial", "coarse".
const char* icp_start_name(IcpStart start);

// Points picked in scan `source` and scan `target` (indices into the scan
// list), each in its own scan frame [m].
struct PickedPairs {
  int source = 0;
  int target = 0;
  std::vector<PointPair> pairs;
};

struct RegistrationSettings {
  CoarseMethod coarse = CoarseMethod::kFeatures;
  // For kPointPairs: for every scan after the first, one entry whose
  // source is that scan and whose target is an earlier scan.
  std::vector<PickedPairs> picks;
  FeatureSettings features;
  SampleSettings icp_sample;  // the source samples of ICP and global refinement
  IcpSettings icp;
  GlobalSettings global;
  bool refine_globally = true;
  // A pair is registered only when ICP converges with at least this share
  // of the source samples matched and at most max_free_space_violation of
  // them in the target's free space (association.hpp); otherwise it is
  // reported as failed and the source scan keeps its initial pose. The same
  // two tests refuse coarse poses.
  double min_overlap = 0.1;
  double max_free_space_violation = 0.03;
  // Pairs matched at least this share at the registered poses join the
  // global refinement (loop closures included).
  double min_global_overlap = 0.05;
  // Of the earlier scans whose samples reach a scan's (the share of its
  // thinned samples within a reach of theirs, at least min_global_overlap),
  // the overlap tests take at most this many, those reached most: the pose
  // graph keeps its strong links, and the tests grow with the number of
  // scans, not with how many see each other down a long street.
  std::size_t max_overlap_tests_per_scan = 6;
  // Samples per scan (thinned evenly) for the overlap and free-space shares
  // that only decide: a coarse pose's tests, and which pairs join the
  // global refinement. Reported figures use every sample.
  std::size_t estimate_samples = 10000;
};

struct CoarseReport {
  CoarseMethod method = CoarseMethod::kNone;
  // The coarse pose was produced and passed its tests; for features also:
  // ICP from it ended at the chosen pose (not beaten by the initial pose).
  bool success = false;
  double inlier_ratio = 0.0;  // features: the chosen hypothesis's inliers / feature matches
  // Features: the share of the thinned ICP samples (estimate_samples)
  // matched, and in the target's free space, after the verifying ICP from
  // the chosen hypothesis.
  double overlap = 0.0;
  double free_space_violation = 0.0;
  double rms_m = 0.0;     // point pairs: residual RMS of the fit
  std::size_t count = 0;  // features: inliers; point pairs: pairs
  // When success: the fit of the picked pairs, or the chosen feature
  // hypothesis after its verifying ICP on the thinned sample.
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  double seconds = 0.0;
  std::string failure;
};

struct PairReport {
  int source = 0;
  int target = 0;
  CoarseReport coarse;
  IcpResult icp;  // the fine stage from the chosen start
  IcpStart start = IcpStart::kInitial;
  bool registered = false;
  std::string failure;   // why registered is false
  double seconds = 0.0;  // coarse stage and every ICP run of the pair
};

// An overlapping pair measured at the final poses.
struct EdgeReport {
  int source = 0;
  int target = 0;
  AlignmentQuality quality;
};

struct RegistrationResult {
  std::vector<Eigen::Isometry3d> T_world_scan;  // final poses; scan 0 keeps its initial pose
  std::vector<PairReport> pairs;                // one per scan after the first
  GlobalResult global;                          // rounds == 0 when not run
  std::vector<EdgeReport> edges;                // every pair above min_global_overlap
  // Overall: point-to-plane RMS and share matched over all edges, the sum of
  // correspondences and iterations, and whether every pair registered and
  // the global refinement converged.
  double rms_m = 0.0;
  double overlap = 0.0;
  std::size_t correspondences = 0;
  int iterations = 0;
  bool converged = false;
  // Pairs of scans tested against each other: registered as a pair, or
  // measured for overlap to decide the global refinement's edges.
  std::size_t pair_tests = 0;
  // Visits of an edge's target by the global refinement and the report:
  // through the edge's patch, and through the whole target scan (a pose
  // left the patch, or the target has no spherical grid).
  std::size_t patch_visits = 0;
  std::size_t scan_visits = 0;
  // Sampling, features, matching, hypotheses and their verifying ICP runs.
  double coarse_seconds = 0.0;
  double fine_seconds = 0.0;  // ICP of every pair and the global refinement
  double seconds = 0.0;       // everything
};

// Registers `scans` (prepared, with their pose guesses `initial_T_world_scan`,
// one per scan; asserted). The first scan is the reference and keeps its
// pose. For kPointPairs, asserts a pick for every later scan (the caller
// validates user input first). Non-convergence and failed pairs are fields
// of the result, not errors. With `progress`, reports one unit per scan
// made ready, per pair and for the global refinement, and throws
// core::Cancelled between them once cancellation is requested.
//
// Scans are taken from `scans` a few at a time: each scan and its target
// for the pairs (the features of two scans in hand), every target once for
// the overlap tests of the pairs whose samples' bounds meet, where a patch
// of it is made for every pair that overlaps (target_patch.hpp). The rounds
// of the global refinement and the report read the patches, and take a
// target again only where a pose leaves its patch. What is kept of every
// scan is its ICP sample cloud, and of every pair its patch.
RegistrationResult register_scans(ScanStream& scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings,
                                  core::Progress* progress = nullptr);

// The same over scans in memory.
RegistrationResult register_scans(std::span<const PreparedScan> scans,
                                  std::span<const Eigen::Isometry3d> initial_T_world_scan,
                                  const RegistrationSettings& settings,
                                  core::Progress* progress = nullptr);

}  // namespace scanbench::registration

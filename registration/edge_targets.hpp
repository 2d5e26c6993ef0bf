// The target side of a registration's edges (pairs of overlapping scans):
// visited target by target, each target scan taken from the stream once,
// and kept between visits as a patch per edge (target_patch.hpp), so that
// a stage that measures the same edges again and again at poses that move
// little (the rounds of the global refinement, then the report of the
// links) loads a target scan only where a pose left its patch.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "acquisition/spherical_grid.hpp"
#include "core/spill_shelf.hpp"
#include "registration/prepared_scan.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/scan_stream.hpp"
#include "registration/target_patch.hpp"

namespace scanbench::registration {

// An overlapping pair: samples of `source` are matched into `target`.
struct ScanEdge {
  int source = 0;
  int target = 0;
  auto operator<=>(const ScanEdge&) const = default;
};

// Calls visit(target scan, edge index) for every edge, target by target in
// ascending order (each target taken from `scans` once, after announcing
// the order), the edges of a target in their order.
void for_each_target(ScanStream& scans, std::span<const ScanEdge> edges,
                     const std::function<void(const PreparedScan&, std::size_t)>& visit);

// The patches of a registration's edges, made while their target scans
// were in hand and parked in a temporary file as the samples are (a patch
// of 40 000 samples takes about 15 MB), with the grids of their targets.
class EdgePatches {
 public:
  // Patches hold the pixels within `margin` rows and columns of each
  // sample's (patch_of).
  explicit EdgePatches(std::size_t scans, int margin = 1);

  // Makes the patch of `edge` anew around `source`'s samples at
  // T_target_source, when `target` (the edge's target scan) has a
  // spherical grid and the temporary file takes the patch; otherwise the
  // edge has no patch.
  void make(const ScanEdge& edge, const SampleCloud& source, const PreparedScan& target,
            const Eigen::Isometry3d& T_target_source);

  // Lets the patch of `edge` go.
  void drop(const ScanEdge& edge);

  // Visits each of `edges` once: through its patch with through_patch(patch,
  // e), which returns false when the patch lacks a pixel it needs; then the
  // edges without a patch or whose patch fell short, target by target as
  // for_each_target, through the whole scan with through_scan(target, e)
  // (which may make the edge's patch anew).
  void visit(ScanStream& scans, std::span<const ScanEdge> edges,
             const std::function<bool(const PatchedTarget&, std::size_t)>& through_patch,
             const std::function<void(const PreparedScan&, std::size_t)>& through_scan);

  // Edges visited through a patch, and through the whole target scan.
  std::size_t patch_visits() const { return patch_visits_; }
  std::size_t scan_visits() const { return scan_visits_; }

 private:
  int margin_;
  core::SpillShelf<TargetPatch> shelf_;
  std::map<ScanEdge, std::size_t> slots_;  // the shelf's slot of each edge's patch
  std::vector<std::optional<acquisition::SphericalGrid>> grids_;  // per target scan
  std::size_t patch_visits_ = 0;
  std::size_t scan_visits_ = 0;
};

}  // namespace scanbench::registration

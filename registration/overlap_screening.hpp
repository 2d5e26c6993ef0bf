// Which registered scans overlap, found without measuring every pair: the
// samples' bounds and occupied cells screen the pairs, and only the
// screened ones are measured on their target scan. Then the report of the
// pairs found, at the final poses.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "registration/edge_targets.hpp"
#include "registration/global_refinement.hpp"
#include "registration/register_scans.hpp"
#include "registration/sample_shelf.hpp"
#include "registration/scan_stream.hpp"

namespace scanbench::registration {

// The pairs of registered scans (`registered`) that overlap at the poses
// T_first_scan, each (source, target) with source > target; `samples`
// holds every scan's ICP samples. Adds each pair measured to `pair_tests`,
// and makes the patch of each pair found on `patches`.
std::vector<ScanEdge> overlapping_edges(ScanStream& scans, SampleShelf& samples,
                                        EdgePatches& patches,
                                        const std::vector<Eigen::Isometry3d>& T_first_scan,
                                        const std::vector<bool>& registered,
                                        const RegistrationSettings& settings,
                                        std::size_t& pair_tests);

// Measures each of `edges` at T_first_scan into result.edges, and the
// overall RMS, correspondences and overlap of `result`; through the edges'
// patches where they hold the pixels the poses need.
void report_edges(ScanStream& scans, SampleShelf& samples, EdgePatches& patches,
                  const std::vector<Eigen::Isometry3d>& T_first_scan,
                  const std::vector<ScanEdge>& edges, const RegistrationSettings& settings,
                  RegistrationResult& result);

}  // namespace scanbench::registration

// Objects carried again when scans move. A commit carries its object from
// the scan it was drawn in into every other scan at the poses of the time
// (object_carry.hpp), and marks the points it carried in the scan's
// `carried` layer (u8). When a registration moves the scans, or registers
// a scan imported after the objects were drawn, those points no longer
// sample the object's surface, or the new scan has none: the carried
// points go back to the pool and every object is carried again, at the
// new poses, from the points drawn in each scan, with the settings its
// commit grew with. A separate marks the object's points in its scan
// drawn: the parts stay as the user split them. Internal to modeling/
// (register uses it).
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "core/progress.hpp"
#include "modeling/store/project.hpp"
#include "registration/scan_stream.hpp"

namespace scanbench::modeling {

struct CarriedAgain {
  // The scans whose objects changed: their membership and carried layers.
  std::map<std::int64_t, std::vector<std::uint32_t>> memberships;
  std::map<std::int64_t, std::vector<std::uint8_t>> carried;
  std::size_t released = 0;        // carried points that went back to the pool
  std::size_t carried_points = 0;  // points carried at the new poses
};

// Carries every object its commit carried again, between the project's
// `scans` (summaries, in order) taken from `stream` (the same scans by
// position, with their geometry), at `poses` (one per scan, in their
// order). Decodes each scan's membership and carried layers once, keeping
// only the pixels its objects were drawn on, and once more as a target;
// holds the changed layers. Takes each target from the stream with the
// scans that have drawn objects. Reports progress per target scan as the
// "register" stage, and throws core::Cancelled when cancelled.
CarriedAgain carry_objects_again(const store::Project& project,
                                 std::span<const store::StoredScanSummary> scans,
                                 registration::ScanStream& stream,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 core::Progress& progress);

// Scan `scan_id`'s carried layer; all 0 (drawn, or still to be segmented)
// when it has none.
std::vector<std::uint8_t> load_carried(const store::Project& project, std::int64_t scan_id,
                                       std::size_t pixels);

}  // namespace scanbench::modeling

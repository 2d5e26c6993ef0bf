// The segmentation's commands (seed 004 §4.1): a region grown from a seed
// into a scan's selection, the selection committed as an object of the
// tree, an object separated into its parts, and automatic proposals.
// Regions grow only through pixels still to be segmented. A selection is
// session state (SelectionTools keeps it): growing one writes nothing, and
// it is kept in the project (a scan's "selection" layer, u8) only on
// request. Every other command here is one journaled command
// (store/project.hpp) that reads and computes first, then writes in one
// Edit.
//
// Errors: a scan or node that does not exist, a seed outside the grid, a
// scan without geometry, growing, proposals or parts in an unstructured
// cloud (a scattered scan has no range image), an empty selection, a bad
// name (tree_commands.hpp):
// core::InputError naming it, and nothing written.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/range_noise.hpp"
#include "modeling/store/project.hpp"
#include "modeling/tree_commands.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/pixel_set.hpp"
#include "segmentation/proposals.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::modeling {

enum class SelectMode {
  kReplace,   // the region becomes the selection
  kAdd,       // the region joins the selection
  kSubtract,  // the region leaves the selection
};

struct SelectSettings {
  std::int64_t scan_id = 0;
  int seed_row = 0;
  int seed_col = 0;
  SelectMode mode = SelectMode::kReplace;
  segmentation::GrowSettings grow;
  segmentation::Constraints constraints;  // image coordinates (constraints.hpp)
  // The scan's σ(range) for the range channel's tests; none: the one its
  // geometry estimated (ScanGeometry::range_noise).
  std::optional<acquisition::RangeNoise> range_noise;
};

struct SelectResult {
  std::size_t region_pixels = 0;    // grown from the seed
  std::size_t selected_pixels = 0;  // in the selection afterwards
  // The seed could grow: usable, open (still to be segmented, inside the
  // lasso, off the barriers) and with a value on the channel.
  bool seed_open = false;
  std::string refused;  // why it could not ("it lies outside the lasso"); empty when it grew
};

// Grows a region from the seed and combines it with `selection`, the
// scan's selection so far. Writes nothing. A seed that cannot grow leaves
// `selection` as it was and says why in `refused`.
SelectResult select_region(const store::Project& project, const SelectSettings& settings,
                           segmentation::PixelSet& selection);

// The selection kept in the project for scan `scan_id` (empty: none).
segmentation::PixelSet kept_selection(const store::Project& project, std::int64_t scan_id);

// Keeps `selections` (scan id → its selection; an empty one removes the
// kept one) in the project as one command, "keep_selection"; returns its id.
std::int64_t keep_selections(store::Project& project,
                             const std::map<std::int64_t, segmentation::PixelSet>& selections);

struct CommitSettings {
  std::int64_t scan_id = 0;
  std::string name;                    // the new object's
  std::optional<std::int64_t> parent;  // a group; none: a root
  // The points of the other scans that sample the object's surface join it
  // too, where they are still to be segmented: an object covers the model,
  // not only the scan it was drawn in.
  bool other_scans = true;
  // Where the drawn scan never saw the object's surface, its points in the
  // other scans grow on from those it carried, with these settings (the
  // channel and tolerance the selection was grown with) and within the
  // object's box (object_carry.hpp). None: only the points on the surfaces
  // the selection covers.
  std::optional<segmentation::GrowSettings> grow = std::nullopt;
  // One σ(range) for every scan; none: each scan's own, as its geometry
  // estimated it.
  std::optional<acquisition::RangeNoise> range_noise = std::nullopt;
};

// Makes `selection`, of scan settings.scan_id, a new object: its pixels
// leave the pool still to be segmented, a selection kept for the scan is
// removed, and the object and its
// ancestors get their point count, mean footprint and world bounding box.
// With other_scans, every other scan with geometry, at its stored pose,
// gives the object its points on the same surface as the selection's, and
// with grow the points it grows to where the drawn scan saw nothing
// (object_carry.hpp), in the same command.
NodeCommandResult commit_selection(store::Project& project, const CommitSettings& settings,
                                   const segmentation::PixelSet& selection);

// Makes the selections of several scans (scan id → its selection; a 3D
// selection spans every scan it reaches) one new object, as
// commit_selection does for one; settings.scan_id is not read. With
// other_scans, each scan with geometry that the object's box reaches
// takes, where still to be segmented, its points on the surfaces the other
// scans' selections cover (the points the merge left out of the model
// where another scan sampled the surface more finely), and with grow those
// it grows to. Scans are read through a ScanCache within the memory limit
// (scan_cache.hpp). Refused when no selection has a pixel still to be
// segmented.
NodeCommandResult commit_selections(
    store::Project& project, const CommitSettings& settings,
    const std::map<std::int64_t, segmentation::PixelSet>& selections);

struct SeparateSettings {
  std::int64_t node = 0;     // an object
  std::int64_t scan_id = 0;  // the scan whose pixels are split
};

struct SeparateResult {
  std::int64_t command_id = 0;
  std::vector<std::int64_t> nodes;  // the object (its largest part) first, then the new ones
};

// Splits an object's pixels in one scan into their 8-connected parts: the
// largest stays the object, each other part becomes a new object beside it
// ("NAME 2", "NAME 3", …), with all its figures.
SeparateResult separate_object(store::Project& project, const SeparateSettings& settings);

struct ProposeSettings {
  std::int64_t scan_id = 0;
  std::string group_name = "proposals";  // the group that receives them
  std::optional<std::int64_t> parent;    // of that group; none: a root
  segmentation::ProposalSettings proposals;
  std::optional<acquisition::RangeNoise> range_noise;  // none: the scan's own
};

// Automatic proposals (segmentation/proposals.hpp) on the scan's pixels still
// to be segmented, each committed as an object "proposal K" in a new group,
// for the user to accept (rename, reparent), merge (merge_objects) or reject
// (delete back to the pool). One command: undo takes them all back.
SeparateResult propose_objects(store::Project& project, const ProposeSettings& settings);

}  // namespace scanbench::modeling

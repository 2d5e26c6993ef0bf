// The colour commands (issue 15, seed 004 §4.5): an object's colour edit set
// or reset (`recolor`), and an object's colours made to match another
// object, a region of a scan, or one colour (`clone`). Each is one journaled
// command writing a new version of the target node, so undo restores the
// earlier edit exactly. The scans' colours are never changed
// (modeling/color_pipeline.hpp); scan-level corrections are the harmonize
// command's (harmonize_command.hpp).
//
// Errors: a node or scan that does not exist, parameters out of range, a
// region outside the scan, a source or target without coloured points:
// core::InputError naming it, and nothing written.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "modeling/color_pipeline.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

struct RecolorSettings {
  std::int64_t node = 0;
  store::ColorEdit set;  // the parameters to set; the others stay as they are
  bool reset = false;    // first drop every parameter the node sets (it inherits them again)
};

NodeCommandResult recolor_object(store::Project& project, const RecolorSettings& settings);

// A rectangle of a scan's grid: rows [row_begin, row_end), columns
// [col_begin, col_end).
struct PixelRect {
  std::int64_t scan_id = 0;
  int row_begin = 0;
  int row_end = 0;
  int col_begin = 0;
  int col_end = 0;
};

struct CloneSettings {
  std::int64_t target = 0;
  // Exactly one source: an object (or group: its descendants' points), a
  // region, or a colour (8-bit sRGB).
  std::optional<std::int64_t> source_node;
  std::optional<PixelRect> source_region;
  std::optional<std::array<std::uint8_t, 3>> source_color;
  // Paint: the target takes the source's mean colour, keeping its own
  // lightness detail (always so for a colour source); otherwise it takes
  // the source's mean and spread in each of L*, a*, b*.
  bool paint = false;
};

struct CloneResult {
  std::int64_t command_id = 0;
  std::int64_t node_id = 0;
  std::size_t source_points = 0;  // 1 for a colour source
  std::size_t target_points = 0;
  store::LabTransfer transfer;  // now the target's own
};

// Statistics transfer in L*a*b* (Reinhard et al.'s idea, in CIELAB): the
// source's colours as shown (its scans' corrections and its edits; for a
// region, its points in the model, deleted ones left out), the target's as
// its scans' corrections leave them, over the points the transfer reaches
// (a group's descendants that set their own transfer keep it and are left
// out). The target gets the transfer and neutral adjustments of its own,
// so nothing it inherits bends the match. The transfer is fixed when
// cloned: a later harmonize changes the target's colours under it.
CloneResult clone_color(store::Project& project, const CloneSettings& settings);

}  // namespace scanbench::modeling

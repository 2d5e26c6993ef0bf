// Non-destructive colour edits (seed 004 §4.5): the scans keep the colours
// they recorded; what the model shows is those colours through
//   1. the scan's colour correction (from `harmonize`): a 3 × 3 matrix and an
//      offset in linear RGB, where exposure and white balance are gains;
//   2. the owning object's edit, in CIE L*a*b*: a statistics transfer (from
//      `recolor --clone` or `--paint`), then gamma, contrast and brightness on
//      L*, then a hue rotation and a saturation (chroma) factor on a*b*.
// An object's edit (store/color_edit.hpp) is a set of optional parameters:
// each one it does not set it inherits from its parent group, so
// brightening a building brightens its walls unless a wall sets its own
// brightness.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "modeling/store/color_edit.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {

// A node's edit with every parameter resolved through its ancestors.
struct ResolvedColorEdit {
  double brightness = 0.0;
  double contrast = 1.0;
  double gamma = 1.0;
  double hue_deg = 0.0;
  double saturation = 1.0;
  store::LabTransfer transfer;
  bool identity() const;
};

// `own`'s parameters over `inherited`'s.
ResolvedColorEdit resolve(const store::ColorEdit& own, const ResolvedColorEdit& inherited);

// Every node's resolved edit, by id (parents before children whatever the
// order of `nodes`; a node whose parent is missing resolves from neutral).
std::map<std::int64_t, ResolvedColorEdit> resolve_color_edits(
    const std::vector<store::ObjectNode>& nodes);

// The edit applied to a colour in L*a*b*.
Eigen::Vector3d apply(const ResolvedColorEdit& edit, const Eigen::Vector3d& lab);

// Colours as the model shows them: per scan its correction, per object its
// resolved edit. Built once per render model (or clone) and read for every
// point.
class ColorPipeline {
 public:
  ColorPipeline(std::map<std::int64_t, store::ScanColorCorrection> corrections,
                std::map<std::int64_t, ResolvedColorEdit> edits);

  // The shown colour of a point of scan `scan_id` recorded as `rgb` and
  // owned by node `node` (0: none). Bit-exactly `rgb` when neither the
  // scan nor the node has an edit.
  std::array<std::uint8_t, 3> shown(std::int64_t scan_id, std::int64_t node,
                                    const std::array<std::uint8_t, 3>& rgb) const;

  // The colour after the scan's correction only, in L*a*b*.
  Eigen::Vector3d corrected_lab(std::int64_t scan_id, const std::array<std::uint8_t, 3>& rgb) const;

 private:
  std::map<std::int64_t, store::ScanColorCorrection> corrections_;
  std::map<std::int64_t, ResolvedColorEdit> edits_;
};

}  // namespace scanbench::modeling

// Non-destructive colour edits (seed 004 §4.5): the scans keep the colours
// they recorded; what the model shows is those colours through
//   1. the scan's colour correction (from `harmonize`): a 3 × 3 matrix and an
//      offset in linear RGB, where exposure and white balance are gains;
//   2. the owning object's edit, in CIE L*a*b*: a statistics transfer (from
//      `recolor --clone` or `--paint`), then gamma, contrast and brightness on
//      L*, then a hue rotation and a saturation (chroma) factor on a*b*.
// An object's edit is a set of optional parameters: each one it does not
// set it inherits from its parent group, so brightening a building
// brightens its walls unless a wall sets its own brightness.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "registration/color_correction.hpp"

namespace scanbench::modeling {

struct ObjectNode;

// Per-channel affine map in L*a*b*: lab' = scale ∘ lab + offset.
struct LabTransfer {
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  bool operator==(const LabTransfer&) const = default;
};

// What one node sets; unset parameters come from its parent.
struct ColorEdit {
  std::optional<double> brightness;  // added to L* [L* units, −100…100]
  std::optional<double> contrast;    // L* scaled about 50 (> 0; 1: none)
  std::optional<double> gamma;       // L*/100 raised to 1 / gamma (> 0.05; > 1 lightens mid-tones)
  std::optional<double> hue_deg;     // a*b* rotated [°]
  std::optional<double> saturation;  // a*b* scaled (≥ 0; 0: grey)
  std::optional<LabTransfer> transfer;
  bool empty() const {
    return !brightness && !contrast && !gamma && !hue_deg && !saturation && !transfer;
  }
  bool operator==(const ColorEdit&) const = default;
};

// A node's edit with every parameter resolved through its ancestors.
struct ResolvedColorEdit {
  double brightness = 0.0;
  double contrast = 1.0;
  double gamma = 1.0;
  double hue_deg = 0.0;
  double saturation = 1.0;
  LabTransfer transfer;
  bool identity() const;
};

// `own`'s parameters over `inherited`'s.
ResolvedColorEdit resolve(const ColorEdit& own, const ResolvedColorEdit& inherited);

// Every node's resolved edit, by id (parents before children whatever the
// order of `nodes`; a node whose parent is missing resolves from neutral).
std::map<std::int64_t, ResolvedColorEdit> resolve_color_edits(const std::vector<ObjectNode>& nodes);

// The edit applied to a colour in L*a*b*.
Eigen::Vector3d apply(const ResolvedColorEdit& edit, const Eigen::Vector3d& lab);

// A scan's correction in linear RGB: rgb' = matrix · rgb + offset; the type
// the harmonisation solves.
using ScanColorCorrection = registration::ColorCorrection;

// JSON of an edit (only the parameters it sets; "" for none) and of a
// correction, as the project stores them. The readers throw
// std::invalid_argument naming the problem (the project adds the file and
// record).
std::string to_json(const ColorEdit& edit);
ColorEdit color_edit_from_json(const std::string& json);
std::string to_json(const ScanColorCorrection& correction);
ScanColorCorrection scan_color_correction_from_json(const std::string& json);

// Checks an edit's parameters (finite, in range); the problem, or "" when
// it is sound.
std::string check_color_edit(const ColorEdit& edit);

// Colours as the model shows them: per scan its correction, per object its
// resolved edit. Built once per render model (or clone) and read for every
// point.
class ColorPipeline {
 public:
  ColorPipeline(std::map<std::int64_t, ScanColorCorrection> corrections,
                std::map<std::int64_t, ResolvedColorEdit> edits);

  // The shown colour of a point of scan `scan_id` recorded as `rgb` and
  // owned by node `node` (0: none). Bit-exactly `rgb` when neither the
  // scan nor the node has an edit.
  std::array<std::uint8_t, 3> shown(std::int64_t scan_id, std::int64_t node,
                                    const std::array<std::uint8_t, 3>& rgb) const;

  // The colour after the scan's correction only, in L*a*b*.
  Eigen::Vector3d corrected_lab(std::int64_t scan_id, const std::array<std::uint8_t, 3>& rgb) const;

 private:
  std::map<std::int64_t, ScanColorCorrection> corrections_;
  std::map<std::int64_t, ResolvedColorEdit> edits_;
};

}  // namespace scanbench::modeling

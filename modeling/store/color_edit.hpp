// The colour edits a project stores (seed 004 §4.5): each object node's
// own edit, a set of optional parameters in CIE L*a*b* that its children
// inherit where they set none, and each scan's correction in linear RGB
// (acquisition::ColorCorrection, which `harmonize` solves). What they do to
// a colour is the commands' (modeling/color_pipeline.hpp); here is what
// they are, their JSON and their bounds.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "acquisition/color_space.hpp"

namespace scanbench::store {

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

// A scan's correction in linear RGB: rgb' = matrix · rgb + offset.
using ScanColorCorrection = acquisition::ColorCorrection;

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

}  // namespace scanbench::store

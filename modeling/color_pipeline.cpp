#include "modeling/color_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "acquisition/color_space.hpp"

namespace scanbench::modeling {

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

bool ResolvedColorEdit::identity() const {
  return brightness == 0.0 && contrast == 1.0 && gamma == 1.0 && hue_deg == 0.0 &&
         saturation == 1.0 && transfer == store::LabTransfer{};
}

ResolvedColorEdit resolve(const store::ColorEdit& own, const ResolvedColorEdit& inherited) {
  ResolvedColorEdit out = inherited;
  if (own.brightness) out.brightness = *own.brightness;
  if (own.contrast) out.contrast = *own.contrast;
  if (own.gamma) out.gamma = *own.gamma;
  if (own.hue_deg) out.hue_deg = *own.hue_deg;
  if (own.saturation) out.saturation = *own.saturation;
  if (own.transfer) out.transfer = *own.transfer;
  return out;
}

std::map<std::int64_t, ResolvedColorEdit> resolve_color_edits(
    const std::vector<store::ObjectNode>& nodes) {
  std::map<std::int64_t, const store::ObjectNode*> by_id;
  for (const store::ObjectNode& n : nodes) by_id[n.id] = &n;
  std::map<std::int64_t, ResolvedColorEdit> resolved;
  // Depth-first up the parents; the tree has no cycles (the commands keep
  // it so), but a damaged one must not recurse forever: a node met again
  // on its own path resolves from neutral.
  std::map<std::int64_t, bool> on_path;
  const std::function<ResolvedColorEdit(std::int64_t)> of = [&](std::int64_t id) {
    if (const auto found = resolved.find(id); found != resolved.end()) return found->second;
    const store::ObjectNode& node = *by_id.at(id);
    ResolvedColorEdit inherited;
    on_path[id] = true;
    if (node.parent && by_id.count(*node.parent) && !on_path[*node.parent])
      inherited = of(*node.parent);
    on_path[id] = false;
    return resolved[id] = resolve(node.color, inherited);
  };
  for (const store::ObjectNode& n : nodes) of(n.id);
  return resolved;
}

Eigen::Vector3d apply(const ResolvedColorEdit& edit, const Eigen::Vector3d& lab_in) {
  Eigen::Vector3d lab = edit.transfer.scale.cwiseProduct(lab_in) + edit.transfer.offset;
  double lightness = std::clamp(lab.x(), 0.0, 100.0);
  if (edit.gamma != 1.0) lightness = 100.0 * std::pow(lightness / 100.0, 1.0 / edit.gamma);
  lightness = 50.0 + edit.contrast * (lightness - 50.0) + edit.brightness;
  const double angle = edit.hue_deg * kPi / 180.0;
  const double c = std::cos(angle), s = std::sin(angle);
  const double a = edit.saturation * (c * lab.y() - s * lab.z());
  const double b = edit.saturation * (s * lab.y() + c * lab.z());
  return {std::clamp(lightness, 0.0, 100.0), a, b};
}

ColorPipeline::ColorPipeline(std::map<std::int64_t, store::ScanColorCorrection> corrections,
                             std::map<std::int64_t, ResolvedColorEdit> edits)
    : corrections_(std::move(corrections)) {
  for (auto& [id, edit] : edits) {
    if (!edit.identity()) edits_.emplace(id, edit);
  }
  std::erase_if(corrections_, [](const auto& entry) { return entry.second.identity(); });
}

Eigen::Vector3d ColorPipeline::corrected_lab(std::int64_t scan_id,
                                             const std::array<std::uint8_t, 3>& rgb) const {
  Eigen::Vector3d linear = acquisition::srgb_to_linear_rgb(rgb);
  if (const auto found = corrections_.find(scan_id); found != corrections_.end())
    linear = found->second.apply(linear).cwiseMax(0.0);
  return acquisition::linear_rgb_to_lab(linear);
}

std::array<std::uint8_t, 3> ColorPipeline::shown(std::int64_t scan_id, std::int64_t node,
                                                 const std::array<std::uint8_t, 3>& rgb) const {
  const auto correction = corrections_.find(scan_id);
  const auto edit = node == 0 ? edits_.end() : edits_.find(node);
  if (correction == corrections_.end() && edit == edits_.end()) return rgb;
  if (edit == edits_.end())
    return acquisition::linear_rgb_to_srgb(
        correction->second.apply(acquisition::srgb_to_linear_rgb(rgb)));
  return acquisition::lab_to_srgb(apply(edit->second, corrected_lab(scan_id, rgb)));
}

}  // namespace scanbench::modeling

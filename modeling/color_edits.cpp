#include "modeling/color_edits.hpp"

#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "acquisition/color_space.hpp"
#include "modeling/project.hpp"

namespace scanbench::modeling {

namespace {

constexpr double kPi = 3.14159265358979323846;

nlohmann::json vector_json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

Eigen::Vector3d vector_of(const nlohmann::json& j, const char* what) {
  if (!j.is_array() || j.size() != 3)
    throw std::invalid_argument(std::string(what) + " is not an array of 3 numbers");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) {
    if (!j[static_cast<std::size_t>(k)].is_number())
      throw std::invalid_argument(std::string(what) + " is not an array of 3 numbers");
    v[k] = j[static_cast<std::size_t>(k)].get<double>();
  }
  return v;
}

nlohmann::json parse_object(const std::string& json) {
  nlohmann::json j = nlohmann::json::parse(json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw std::invalid_argument("not a JSON object");
  return j;
}

}  // namespace

bool ResolvedColorEdit::identity() const {
  return brightness == 0.0 && contrast == 1.0 && gamma == 1.0 && hue_deg == 0.0 &&
         saturation == 1.0 && transfer == LabTransfer{};
}

ResolvedColorEdit resolve(const ColorEdit& own, const ResolvedColorEdit& inherited) {
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
    const std::vector<ObjectNode>& nodes) {
  std::map<std::int64_t, const ObjectNode*> by_id;
  for (const ObjectNode& n : nodes) by_id[n.id] = &n;
  std::map<std::int64_t, ResolvedColorEdit> resolved;
  // Depth-first up the parents; the tree has no cycles (the commands keep
  // it so), but a damaged one must not recurse forever: a node met again
  // on its own path resolves from neutral.
  std::map<std::int64_t, bool> on_path;
  const std::function<ResolvedColorEdit(std::int64_t)> of = [&](std::int64_t id) {
    if (const auto found = resolved.find(id); found != resolved.end()) return found->second;
    const ObjectNode& node = *by_id.at(id);
    ResolvedColorEdit inherited;
    on_path[id] = true;
    if (node.parent && by_id.count(*node.parent) && !on_path[*node.parent])
      inherited = of(*node.parent);
    on_path[id] = false;
    return resolved[id] = resolve(node.color, inherited);
  };
  for (const ObjectNode& n : nodes) of(n.id);
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

std::string check_color_edit(const ColorEdit& edit) {
  const auto finite = [](const std::optional<double>& v) { return !v || std::isfinite(*v); };
  if (!finite(edit.brightness) || !finite(edit.contrast) || !finite(edit.gamma) ||
      !finite(edit.hue_deg) || !finite(edit.saturation))
    return "colour edit parameters must be finite numbers";
  if (edit.brightness && std::abs(*edit.brightness) > 100.0)
    return "brightness must be within -100 and 100 (L* units)";
  if (edit.contrast && (*edit.contrast <= 0.0 || *edit.contrast > 10.0))
    return "contrast must be above 0 and at most 10";
  if (edit.gamma && (*edit.gamma <= 0.05 || *edit.gamma > 20.0))
    return "gamma must be above 0.05 and at most 20";
  if (edit.saturation && (*edit.saturation < 0.0 || *edit.saturation > 10.0))
    return "saturation must be within 0 and 10";
  if (edit.transfer && (!edit.transfer->scale.allFinite() || !edit.transfer->offset.allFinite() ||
                        (edit.transfer->scale.array() < 0.0).any()))
    return "a colour transfer must have finite, non-negative scales and finite offsets";
  return {};
}

std::string to_json(const ColorEdit& edit) {
  if (edit.empty()) return {};
  nlohmann::json j = nlohmann::json::object();
  if (edit.brightness) j["brightness"] = *edit.brightness;
  if (edit.contrast) j["contrast"] = *edit.contrast;
  if (edit.gamma) j["gamma"] = *edit.gamma;
  if (edit.hue_deg) j["hue_deg"] = *edit.hue_deg;
  if (edit.saturation) j["saturation"] = *edit.saturation;
  if (edit.transfer) {
    j["transfer"] = {{"scale", vector_json(edit.transfer->scale)},
                     {"offset", vector_json(edit.transfer->offset)}};
  }
  return j.dump();
}

ColorEdit color_edit_from_json(const std::string& json) {
  ColorEdit edit;
  if (json.empty()) return edit;
  const nlohmann::json j = parse_object(json);
  const auto number = [&](const char* key, std::optional<double>& to) {
    if (!j.contains(key)) return;
    if (!j[key].is_number()) throw std::invalid_argument(std::string(key) + " is not a number");
    to = j[key].get<double>();
  };
  number("brightness", edit.brightness);
  number("contrast", edit.contrast);
  number("gamma", edit.gamma);
  number("hue_deg", edit.hue_deg);
  number("saturation", edit.saturation);
  if (j.contains("transfer")) {
    const nlohmann::json& t = j["transfer"];
    if (!t.is_object() || !t.contains("scale") || !t.contains("offset"))
      throw std::invalid_argument("transfer needs a scale and an offset");
    edit.transfer = LabTransfer{vector_of(t["scale"], "transfer scale"),
                                vector_of(t["offset"], "transfer offset")};
  }
  if (const std::string problem = check_color_edit(edit); !problem.empty())
    throw std::invalid_argument(problem);
  return edit;
}

std::string to_json(const ScanColorCorrection& correction) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(vector_json(correction.matrix.row(r).transpose()));
  return nlohmann::json{{"matrix", rows}, {"offset", vector_json(correction.offset)}}.dump();
}

ScanColorCorrection scan_color_correction_from_json(const std::string& json) {
  const nlohmann::json j = parse_object(json);
  if (!j.contains("matrix") || !j["matrix"].is_array() || j["matrix"].size() != 3 ||
      !j.contains("offset"))
    throw std::invalid_argument("a colour correction needs a 3 × 3 matrix and an offset");
  ScanColorCorrection c;
  for (int r = 0; r < 3; ++r)
    c.matrix.row(r) = vector_of(j["matrix"][static_cast<std::size_t>(r)], "matrix row").transpose();
  c.offset = vector_of(j["offset"], "offset");
  if (!c.matrix.allFinite() || !c.offset.allFinite())
    throw std::invalid_argument("a colour correction must be finite");
  return c;
}

ColorPipeline::ColorPipeline(std::map<std::int64_t, ScanColorCorrection> corrections,
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

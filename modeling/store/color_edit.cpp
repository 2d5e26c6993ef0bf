#include "modeling/store/color_edit.hpp"

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace scanbench::store {

namespace {

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

}  // namespace scanbench::store

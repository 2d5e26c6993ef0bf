#include "modeling/command_json.hpp"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <numbers>

#include "acquisition/formats/scan_files.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/register_command.hpp"
#include "modeling/selection_commands.hpp"
#include "registration/merge.hpp"
#include "registration/register_scans.hpp"

// The field lists below are the whole structs minus `threads`.

namespace scanbench::acquisition {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RangeNoise, noise_m, noise_per_m, noise_per_m2)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GeometrySettings, window_radius, edge_window_radius,
                                                depth_jump_sigmas, depth_jump_relative,
                                                min_neighbours, max_footprint_stretch,
                                                flag_mixed_pixels, range_noise, mixed_pixel_sigmas,
                                                mixed_pixel_relative, estimate_range_noise)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SphericalFitSettings, max_deviation_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(LocalOriginSettings, angle_fit,
                                                max_per_pixel_range_m, max_error_m, try_spherical)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PtxReadSettings, grid)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ScanFileSettings, ptx)
}  // namespace scanbench::acquisition

// A noise model the user may leave to each scan: null when none.
template <>
struct nlohmann::adl_serializer<std::optional<scanbench::acquisition::RangeNoise>> {
  static void to_json(json& j, const std::optional<scanbench::acquisition::RangeNoise>& noise) {
    j = noise ? json(*noise) : json(nullptr);
  }
  static void from_json(const json& j, std::optional<scanbench::acquisition::RangeNoise>& noise) {
    if (j.is_null()) {
      noise.reset();
    } else {
      noise = j.get<scanbench::acquisition::RangeNoise>();
    }
  }
};

namespace scanbench::registration {
// Enums as the reports spell them (coarse_method_name, color_model_name).
static void to_json(nlohmann::json& j, CoarseMethod method) {
  j = coarse_method_name(method);
}
static void from_json(const nlohmann::json& j, CoarseMethod& method) {
  const std::optional<CoarseMethod> named = coarse_method_from_name(j.get<std::string>());
  if (!named) {
    throw core::InputError("", {{}, {}, "key \"coarse\""},
                           "unknown coarse method '" + j.get<std::string>() + "'");
  }
  method = *named;
}
static void to_json(nlohmann::json& j, ColorModel model) {
  j = std::string(color_model_name(model));
}
static void from_json(const nlohmann::json& j, ColorModel& model) {
  for (const ColorModel m : {ColorModel::kGainOffset, ColorModel::kMatrix}) {
    if (color_model_name(m) == j.get<std::string>()) {
      model = m;
      return;
    }
  }
  throw core::InputError("", {{}, {}, "key \"model\""},
                         "unknown colour model '" + j.get<std::string>() + "'");
}
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SampleSettings, voxel_m, max_points)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(HypothesisSettings, draws, inlier_distance_m,
                                                max_vertical_normal, scoring_matches, keep,
                                                distinct_rotation_rad, distinct_translation_m, seed)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FeatureSettings, sample, feature_radius_m,
                                                neighbours, levelled, max_normal_z_difference,
                                                hypotheses, max_iterations, similarity, min_inliers,
                                                verify_by_inliers, verify_by_overlap,
                                                screening_samples)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(IcpSettings, initial_gate_m, min_gate_m,
                                                projective_gate_m, closest_point_samples,
                                                distance_sigmas, min_gate_ratio,
                                                max_normal_angle_deg, loss_scale_m, max_iterations,
                                                solver_iterations, stop_rotation_rad,
                                                stop_translation_m, min_correspondences)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GlobalSettings, max_rounds, solver_iterations,
                                                max_samples, initial_gate_m, icp)

static void to_json(nlohmann::json& j, const PointPair& p) {
  j = {{"source", {p.source.x(), p.source.y(), p.source.z()}},
       {"target", {p.target.x(), p.target.y(), p.target.z()}}};
}
static void from_json(const nlohmann::json& j, PointPair& p) {
  const auto source = j.at("source").get<std::array<double, 3>>();
  const auto target = j.at("target").get<std::array<double, 3>>();
  p.source = Eigen::Vector3d(source[0], source[1], source[2]);
  p.target = Eigen::Vector3d(target[0], target[1], target[2]);
}

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PickedPairs, source, target, pairs)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegistrationSettings, coarse, picks, features,
                                                icp_sample, icp, global, refine_globally,
                                                min_overlap, max_free_space_violation,
                                                min_global_overlap, max_overlap_tests_per_scan,
                                                estimate_samples)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MergeSettings, noise, range_sigmas,
                                                max_normal_angle_deg, tie_tolerance,
                                                bound_coarser_scans)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ColorPairSettings, stride, phase, max_distance_m,
                                                max_normal_angle_deg, dark, bright, max_local_step,
                                                max_pairs_per_overlap, max_pairs_per_scan)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(HarmonizeSettings, model, loss_scale, prior_weight,
                                                max_gain_ratio, max_cross_talk, max_offset,
                                                max_iterations)
}  // namespace scanbench::registration

namespace scanbench::modeling {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ProjectPicks, source_id, target_id, pairs)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegisterCommandSettings, registration, picks)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ImportSettings, readers, allow_duplicates)

// Harmonize's settings are one flat object, the pair search's keys beside
// the solve's (no name is in both), as the journal has always stored them.
static void to_json(nlohmann::json& j, const HarmonizeCommandSettings& s) {
  j = nlohmann::json(s.pairs);
  j.update(nlohmann::json(s.solve));
}
static void from_json(const nlohmann::json& j, HarmonizeCommandSettings& s) {
  const nlohmann::json pairs_keys = nlohmann::json(registration::ColorPairSettings{});
  nlohmann::json pairs = nlohmann::json::object();
  nlohmann::json solve = nlohmann::json::object();
  for (const auto& [key, value] : j.items())
    (pairs_keys.contains(key) ? pairs : solve)[key] = value;
  s.pairs = pairs.get<registration::ColorPairSettings>();
  s.solve = solve.get<registration::HarmonizeSettings>();
}

namespace {

constexpr const char* kModes[] = {"replace", "add", "subtract"};

nlohmann::json polyline_json(const segmentation::Polyline& line) {
  nlohmann::json out = nlohmann::json::array();
  for (const Eigen::Vector2d& v : line) out.push_back({v.x(), v.y()});
  return out;
}

segmentation::Polyline polyline_from(const nlohmann::json& j) {
  segmentation::Polyline line;
  for (const nlohmann::json& v : j) {
    const auto xy = v.get<std::array<double, 2>>();
    line.emplace_back(xy[0], xy[1]);
  }
  return line;
}

// A region's grow settings, flat: the keys of select and commit.
nlohmann::json grow_json(const segmentation::GrowSettings& g) {
  return {{"channel", segmentation::channel_name(g.channel)},
          {"tolerance", g.tolerance},
          {"mean_factor", g.mean_factor},
          {"plane_footprints", g.plane_footprints},
          {"continuity_footprints", g.continuity_footprints},
          {"max_pixels", g.max_pixels}};
}

segmentation::GrowSettings grow_from(const nlohmann::json& j,
                                     const segmentation::GrowSettings& defaults) {
  segmentation::GrowSettings g;
  const std::string channel =
      j.value("channel", std::string(segmentation::channel_name(defaults.channel)));
  const std::optional<segmentation::Channel> named = segmentation::channel_from_name(channel);
  if (!named)
    throw core::InputError("", {{}, {}, "key \"channel\""}, "unknown channel '" + channel + "'");
  g.channel = *named;
  g.tolerance = j.value("tolerance", defaults.tolerance);
  g.mean_factor = j.value("mean_factor", defaults.mean_factor);
  g.plane_footprints = j.value("plane_footprints", defaults.plane_footprints);
  g.continuity_footprints = j.value("continuity_footprints", defaults.continuity_footprints);
  g.max_pixels = j.value("max_pixels", defaults.max_pixels);
  return g;
}

}  // namespace

static void to_json(nlohmann::json& j, const SelectSettings& s) {
  nlohmann::json barriers = nlohmann::json::array();
  for (const segmentation::Polyline& line : s.constraints.barriers)
    barriers.push_back(polyline_json(line));
  j = {{"scan", s.scan_id},
       {"seed", {s.seed_row, s.seed_col}},
       {"mode", kModes[static_cast<int>(s.mode)]},
       {"lasso", polyline_json(s.constraints.lasso)},
       {"barriers", barriers},
       {"range_noise", s.range_noise}};
  j.update(grow_json(s.grow));
}
static void from_json(const nlohmann::json& j, SelectSettings& s) {
  const SelectSettings defaults;
  s.scan_id = j.value("scan", defaults.scan_id);
  const auto seed = j.value("seed", std::array<int, 2>{defaults.seed_row, defaults.seed_col});
  s.seed_row = seed[0];
  s.seed_col = seed[1];
  const std::string mode = j.value("mode", std::string(kModes[0]));
  bool known = false;
  for (int m = 0; m < 3; ++m) {
    if (mode != kModes[m]) continue;
    s.mode = static_cast<SelectMode>(m);
    known = true;
  }
  if (!known) throw core::InputError("", {{}, {}, "key \"mode\""}, "unknown mode '" + mode + "'");
  s.grow = grow_from(j, defaults.grow);
  s.constraints.lasso = polyline_from(j.value("lasso", nlohmann::json::array()));
  for (const nlohmann::json& line : j.value("barriers", nlohmann::json::array()))
    s.constraints.barriers.push_back(polyline_from(line));
  s.range_noise = j.value("range_noise", defaults.range_noise);
}

// Commit: the grow settings (null: none) nested, since they are optional.
static void to_json(nlohmann::json& j, const CommitSettings& s) {
  j = {{"scan", s.scan_id},
       {"name", s.name},
       {"parent", parent_json(s.parent)},
       {"other_scans", s.other_scans},
       {"grow", s.grow ? grow_json(*s.grow) : nlohmann::json(nullptr)},
       {"range_noise", s.range_noise}};
}
static void from_json(const nlohmann::json& j, CommitSettings& s) {
  const CommitSettings defaults;
  s.scan_id = j.value("scan", defaults.scan_id);
  s.name = j.value("name", defaults.name);
  const nlohmann::json parent = j.value("parent", nlohmann::json(nullptr));
  s.parent = parent.is_null() ? std::nullopt : std::optional<std::int64_t>(parent.get<std::int64_t>());
  s.other_scans = j.value("other_scans", defaults.other_scans);
  const nlohmann::json grow = j.value("grow", nlohmann::json(nullptr));
  if (grow.is_null()) {
    s.grow.reset();
  } else {
    // The defaults of the channel named (a tolerance means a different unit
    // on each channel), then what the object sets.
    const segmentation::GrowSettings normal =
        segmentation::default_grow_settings(segmentation::Channel::kNormal);
    s.grow = grow_from(grow, segmentation::default_grow_settings(grow_from(grow, normal).channel));
  }
  s.range_noise = j.value("range_noise", defaults.range_noise);
}

namespace {

// The range checks of settings a user gives (SettingsSource::kUser). Each
// value must lie in [lo, hi]; the bounds keep every count and size within
// what a command can allocate and every threshold meaningful.
class Bounds {
 public:
  explicit Bounds(std::string origin) : origin_(std::move(origin)) {}

  template <typename Value>
  void in(Value value, double lo, double hi, const std::string& key) const {
    const auto v = static_cast<double>(value);
    if (v >= lo && v <= hi) return;
    refuse(key, fmt::format("{} is outside {} to {}", v, lo, hi));
  }
  // A length or a scale: above zero, at most `hi`.
  void positive(double value, double hi, const std::string& key) const {
    if (value > 0 && value <= hi) return;
    refuse(key, fmt::format("{} is not above 0 and at most {}", value, hi));
  }

 private:
  [[noreturn]] void refuse(const std::string& key, const std::string& problem) const {
    throw core::InputError(origin_, {{}, {}, "key \"" + key + "\""}, problem);
  }
  std::string origin_;
};

constexpr double kMaxCount = 1e7;   // samples, matches, pixels
constexpr double kMaxLength = 1e4;  // [m]
constexpr double kMaxRatio = 1e3;   // multiples of a noise or a footprint
constexpr double kMaxIterations = 1e6;

void check(const acquisition::RangeNoise& n, const Bounds& b, const std::string& at) {
  b.in(n.noise_m, 0, 10, at + "noise_m");
  b.in(n.noise_per_m, 0, 1, at + "noise_per_m");
  b.in(n.noise_per_m2, 0, 1, at + "noise_per_m2");
}

void check(const ImportSettings& s, const Bounds& b) {
  const acquisition::LocalOriginSettings& grid = s.readers.ptx.grid;
  b.positive(grid.angle_fit.max_deviation_m, 1, "readers.ptx.grid.angle_fit.max_deviation_m");
  b.positive(grid.max_per_pixel_range_m, 1e5, "readers.ptx.grid.max_per_pixel_range_m");
  b.positive(grid.max_error_m, 1, "readers.ptx.grid.max_error_m");
}

void check(const acquisition::GeometrySettings& s, const Bounds& b) {
  b.in(s.window_radius, 1, acquisition::kMaxWindowRadius, "window_radius");
  b.in(s.edge_window_radius, 1, s.window_radius, "edge_window_radius");
  b.positive(s.depth_jump_sigmas, kMaxRatio, "depth_jump_sigmas");
  b.in(s.depth_jump_relative, 0, 10, "depth_jump_relative");
  b.in(s.min_neighbours, 3, kMaxCount, "min_neighbours");
  b.in(s.max_footprint_stretch, 1, kMaxRatio, "max_footprint_stretch");
  b.positive(s.mixed_pixel_sigmas, kMaxRatio, "mixed_pixel_sigmas");
  b.in(s.mixed_pixel_relative, 0, 10, "mixed_pixel_relative");
  check(s.range_noise, b, "range_noise.");
}

void check(const registration::SampleSettings& s, const Bounds& b, const std::string& at) {
  b.positive(s.voxel_m, kMaxLength, at + "voxel_m");
  b.in(s.max_points, 1, kMaxCount, at + "max_points");
}

void check(const registration::IcpSettings& s, const Bounds& b, const std::string& at) {
  b.positive(s.initial_gate_m, kMaxLength, at + "initial_gate_m");
  b.positive(s.min_gate_m, kMaxLength, at + "min_gate_m");
  b.positive(s.projective_gate_m, kMaxLength, at + "projective_gate_m");
  b.in(s.closest_point_samples, 1, kMaxCount, at + "closest_point_samples");
  b.positive(s.distance_sigmas, kMaxRatio, at + "distance_sigmas");
  b.in(s.min_gate_ratio, 0, 1, at + "min_gate_ratio");
  b.in(s.max_normal_angle_deg, 0, 180, at + "max_normal_angle_deg");
  b.positive(s.loss_scale_m, kMaxLength, at + "loss_scale_m");
  b.in(s.max_iterations, 0, kMaxIterations, at + "max_iterations");
  b.in(s.solver_iterations, 1, kMaxIterations, at + "solver_iterations");
  b.in(s.stop_rotation_rad, 0, std::numbers::pi, at + "stop_rotation_rad");
  b.in(s.stop_translation_m, 0, kMaxLength, at + "stop_translation_m");
  b.in(s.min_correspondences, 3, kMaxCount, at + "min_correspondences");
}

void check(const registration::RegistrationSettings& s, const Bounds& b) {
  const registration::FeatureSettings& f = s.features;
  check(f.sample, b, "registration.features.sample.");
  b.positive(f.feature_radius_m, kMaxLength, "registration.features.feature_radius_m");
  b.in(f.neighbours, 1, 100, "registration.features.neighbours");
  b.in(f.max_normal_z_difference, 0, 2, "registration.features.max_normal_z_difference");
  b.in(f.max_iterations, 1, kMaxIterations * 100, "registration.features.max_iterations");
  b.in(f.similarity, 0, 1, "registration.features.similarity");
  b.in(f.min_inliers, 3, kMaxCount, "registration.features.min_inliers");
  b.in(f.verify_by_inliers, 0, 1e4, "registration.features.verify_by_inliers");
  b.in(f.verify_by_overlap, 0, 1e4, "registration.features.verify_by_overlap");
  b.in(f.screening_samples, 1, kMaxCount, "registration.features.screening_samples");
  const registration::HypothesisSettings& h = f.hypotheses;
  const std::string at = "registration.features.hypotheses.";
  b.in(h.draws, 1, kMaxIterations * 100, at + "draws");
  b.positive(h.inlier_distance_m, kMaxLength, at + "inlier_distance_m");
  b.in(h.max_vertical_normal, 0, 1, at + "max_vertical_normal");
  b.in(h.scoring_matches, 1, kMaxCount, at + "scoring_matches");
  b.in(h.keep, 1, 1e4, at + "keep");
  b.in(h.distinct_rotation_rad, 0, std::numbers::pi, at + "distinct_rotation_rad");
  b.in(h.distinct_translation_m, 0, kMaxLength, at + "distinct_translation_m");
  check(s.icp_sample, b, "registration.icp_sample.");
  check(s.icp, b, "registration.icp.");
  b.in(s.global.max_rounds, 0, 1e4, "registration.global.max_rounds");
  b.in(s.global.solver_iterations, 1, kMaxIterations, "registration.global.solver_iterations");
  b.in(s.global.max_samples, 1, kMaxCount, "registration.global.max_samples");
  b.positive(s.global.initial_gate_m, kMaxLength, "registration.global.initial_gate_m");
  check(s.global.icp, b, "registration.global.icp.");
  b.in(s.min_overlap, 0, 1, "registration.min_overlap");
  b.in(s.max_free_space_violation, 0, 1, "registration.max_free_space_violation");
  b.in(s.min_global_overlap, 0, 1, "registration.min_global_overlap");
  b.in(s.max_overlap_tests_per_scan, 1, kMaxCount, "registration.max_overlap_tests_per_scan");
  b.in(s.estimate_samples, 1, kMaxCount, "registration.estimate_samples");
}

// Which scans the picks name is checked by the command, against the project.
void check(const RegisterCommandSettings& s, const Bounds& b) {
  check(s.registration, b);
}

void check(const registration::MergeSettings& s, const Bounds& b) {
  if (s.noise) check(*s.noise, b, "noise.");
  b.positive(s.range_sigmas, kMaxRatio, "range_sigmas");
  b.in(s.max_normal_angle_deg, 0, 180, "max_normal_angle_deg");
  b.in(s.tie_tolerance, 0, 10, "tie_tolerance");
}

void check(const HarmonizeCommandSettings& s, const Bounds& b) {
  b.in(s.pairs.stride, 1, 1e4, "stride");
  b.in(s.pairs.phase, 0, s.pairs.stride - 1, "phase");
  b.positive(s.pairs.max_distance_m, kMaxLength, "max_distance_m");
  b.in(s.pairs.max_normal_angle_deg, 0, 180, "max_normal_angle_deg");
  b.in(s.pairs.dark, 0, 254, "dark");
  b.in(s.pairs.bright, s.pairs.dark + 1, 255, "bright");
  b.in(s.pairs.max_local_step, 0, 1e4, "max_local_step");
  b.in(s.pairs.max_pairs_per_overlap, 1, kMaxCount, "max_pairs_per_overlap");
  b.in(s.pairs.max_pairs_per_scan, 0, kMaxCount, "max_pairs_per_scan");
  b.positive(s.solve.loss_scale, kMaxRatio, "loss_scale");
  b.in(s.solve.prior_weight, 0, 1e6, "prior_weight");
  b.in(s.solve.max_gain_ratio, 1, kMaxRatio, "max_gain_ratio");
  b.in(s.solve.max_cross_talk, 0, 10, "max_cross_talk");
  b.in(s.solve.max_offset, 0, 10, "max_offset");
  b.in(s.solve.max_iterations, 1, kMaxIterations, "max_iterations");
}

void check(const segmentation::GrowSettings& g, const Bounds& b, const std::string& prefix) {
  b.in(g.tolerance, 0, 1e6, prefix + "tolerance");
  b.in(g.mean_factor, 0, kMaxRatio, prefix + "mean_factor");
  b.in(g.plane_footprints, 0, kMaxRatio, prefix + "plane_footprints");
  b.in(g.continuity_footprints, 0, kMaxRatio, prefix + "continuity_footprints");
}

void check(const SelectSettings& s, const Bounds& b) {
  check(s.grow, b, "");
  if (s.range_noise) check(*s.range_noise, b, "range_noise.");
}

void check(const CommitSettings& s, const Bounds& b) {
  if (s.grow) check(*s.grow, b, "grow.");
  if (s.range_noise) check(*s.range_noise, b, "range_noise.");
}

// Refuses the first place where `given` differs from `read_back`, the
// settings it was read into written again: a key the struct does not have,
// or a value that did not survive the read (2.7 read into a count as 2).
void refuse_what_does_not_read_back(const nlohmann::json& given, const nlohmann::json& read_back,
                                    const std::string& origin, const std::string& key) {
  const auto refuse = [&](const std::string& problem) {
    throw core::InputError(origin, {{}, {}, "key \"" + key + "\""}, problem);
  };
  if (given.is_object() && read_back.is_object()) {
    for (const auto& [name, value] : given.items()) {
      const std::string inner = key.empty() ? name : key + "." + name;
      if (!read_back.contains(name))
        throw core::InputError(origin, {{}, {}, "key \"" + inner + "\""},
                               "unknown key (a thread count is not a setting: use --threads)");
      refuse_what_does_not_read_back(value, read_back.at(name), origin, inner);
    }
    return;
  }
  if (given.is_array() && read_back.is_array() && given.size() == read_back.size()) {
    for (std::size_t i = 0; i < given.size(); ++i) {
      refuse_what_does_not_read_back(given[i], read_back[i], origin,
                                     key + "[" + std::to_string(i) + "]");
    }
    return;
  }
  if (given != read_back)
    refuse(given.dump() + " does not fit (it reads as " + read_back.dump() + ")");
}

template <typename Settings>
Settings read_settings(const nlohmann::json& json, const std::string& origin,
                       SettingsSource source) {
  core::FilePosition position;
  position.detail = "settings";
  try {
    if (!json.is_object()) throw core::InputError(origin, position, "settings are not an object");
    Settings settings = json.get<Settings>();
    if (source == SettingsSource::kUser) {
      refuse_what_does_not_read_back(json, nlohmann::json(settings), origin, "");
      check(settings, Bounds(origin));
    }
    return settings;
  } catch (const core::InputError& e) {
    if (!e.file().empty()) throw;
    throw core::InputError(origin, e.position(), e.problem());
  } catch (const nlohmann::json::exception& e) {
    // The library's text names the key path where it knows it; cut, it stays one line.
    std::string what = e.what();
    if (what.size() > 120) what = what.substr(0, 120) + "…";
    throw core::InputError(origin, position, "unreadable settings: " + what);
  }
}

}  // namespace

std::string dump(const nlohmann::json& json) {
  return json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

template <typename Settings>
std::string settings_to_json(const Settings& settings) {
  return dump(nlohmann::json(settings));
}

template <typename Settings>
Settings settings_from_json(const nlohmann::json& json, const std::string& origin,
                            SettingsSource source) {
  return read_settings<Settings>(json, origin, source);
}

template <typename Settings>
Settings settings_from_json(const std::string& json, const std::string& origin,
                            SettingsSource source) {
  nlohmann::json document;
  try {
    document = nlohmann::json::parse(json);
  } catch (const nlohmann::json::exception&) {
    throw core::InputError(origin, {{}, {}, "settings"}, "not valid JSON");
  }
  return read_settings<Settings>(document, origin, source);
}

#define SCANBENCH_SETTINGS_JSON(Type)                                               \
  template std::string settings_to_json<Type>(const Type&);                         \
  template Type settings_from_json<Type>(const nlohmann::json&, const std::string&, \
                                         SettingsSource);                           \
  template Type settings_from_json<Type>(const std::string&, const std::string&, SettingsSource);

SCANBENCH_SETTINGS_JSON(ImportSettings)
SCANBENCH_SETTINGS_JSON(acquisition::GeometrySettings)
SCANBENCH_SETTINGS_JSON(registration::MergeSettings)
SCANBENCH_SETTINGS_JSON(RegisterCommandSettings)
SCANBENCH_SETTINGS_JSON(HarmonizeCommandSettings)
SCANBENCH_SETTINGS_JSON(SelectSettings)
SCANBENCH_SETTINGS_JSON(CommitSettings)
#undef SCANBENCH_SETTINGS_JSON

template std::string settings_to_json<acquisition::ScanFileSettings>(
    const acquisition::ScanFileSettings&);
template std::string settings_to_json<registration::RegistrationSettings>(
    const registration::RegistrationSettings&);

}  // namespace scanbench::modeling

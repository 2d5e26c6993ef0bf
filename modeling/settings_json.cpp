#include "modeling/settings_json.hpp"

#include <nlohmann/json.hpp>

#include "acquisition/formats/scan_files.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "registration/merge.hpp"
#include "registration/register_scans.hpp"

// The field lists below are the whole structs minus `threads`; a field added
// to a struct must be added here (the round-trip test in
// tests/modeling/test_settings_json.cpp catches a field read but not written).

namespace scanbench::acquisition {
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RangeNoise, noise_m, noise_per_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(GeometrySettings, window_radius, edge_window_radius,
                                                depth_jump_sigmas, depth_jump_relative,
                                                min_neighbours, max_footprint_stretch,
                                                flag_mixed_pixels, range_noise, mixed_pixel_sigmas)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SphericalFitSettings, max_deviation_m)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(LocalOriginSettings, angle_fit,
                                                max_per_pixel_range_m, try_spherical)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(PtxReadSettings, grid)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ScanFileSettings, ptx)
}  // namespace scanbench::acquisition

namespace scanbench::registration {
// The method's name as reports spell it (coarse_method_name).
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
                                                min_global_overlap, estimate_samples)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(MergeSettings, noise, range_sigmas,
                                                max_normal_angle_deg, tie_tolerance,
                                                bound_coarser_scans)
}  // namespace scanbench::registration

namespace scanbench::modeling {

NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ProjectPicks, source_id, target_id, pairs)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegisterCommandSettings, registration, picks)

template <typename Settings>
std::string settings_to_json(const Settings& settings) {
  return nlohmann::json(settings).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

template <typename Settings>
Settings settings_from_json(const std::string& json, const std::string& origin) {
  core::FilePosition position;
  position.detail = origin + " settings";
  try {
    const nlohmann::json document = nlohmann::json::parse(json);
    if (!document.is_object()) throw core::InputError("", position, "settings are not an object");
    return document.get<Settings>();
  } catch (const nlohmann::json::exception& e) {
    // The library's own text names the key path (".icp.min_gate_m") where it knows it.
    // The library's text names the key path where it knows it; cut, it stays one line.
    std::string what = e.what();
    if (what.size() > 120) what = what.substr(0, 120) + "…";
    throw core::InputError("", position, "unreadable settings: " + what);
  }
}

#define SCANBENCH_SETTINGS_JSON(Type)                       \
  template std::string settings_to_json<Type>(const Type&); \
  template Type settings_from_json<Type>(const std::string&, const std::string&);

SCANBENCH_SETTINGS_JSON(acquisition::GeometrySettings)
SCANBENCH_SETTINGS_JSON(acquisition::ScanFileSettings)
SCANBENCH_SETTINGS_JSON(registration::MergeSettings)
SCANBENCH_SETTINGS_JSON(registration::RegistrationSettings)
SCANBENCH_SETTINGS_JSON(RegisterCommandSettings)

#undef SCANBENCH_SETTINGS_JSON

}  // namespace scanbench::modeling

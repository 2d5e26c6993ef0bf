// Settings as whole structs in JSON: every field written is read back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "acquisition/formats/scan_files.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "modeling/settings_json.hpp"
#include "registration/merge.hpp"

namespace scanbench::modeling {
namespace {

// Changes every number and flag of `j`, recursively, so that a field the
// reader drops comes back as its default and shows up as a difference.
void perturb(nlohmann::json& j) {
  if (j.is_object() || j.is_array()) {
    for (auto& value : j) perturb(value);
  } else if (j.is_boolean()) {
    j = !j.get<bool>();
  } else if (j.is_number_unsigned()) {
    j = j.get<std::uint64_t>() + 3;
  } else if (j.is_number_integer()) {
    j = j.get<std::int64_t>() + 3;
  } else if (j.is_number_float()) {
    j = j.get<double>() * 1.5 + 0.25;
  }
}

template <typename Settings>
void expect_every_field_round_trips(Settings settings = {}) {
  nlohmann::json changed = nlohmann::json::parse(settings_to_json(settings));
  perturb(changed);
  const Settings back = settings_from_json<Settings>(changed.dump(), "test");
  EXPECT_EQ(nlohmann::json::parse(settings_to_json(back)), changed);
}

TEST(SettingsJson, GeometryRoundTrips) {
  expect_every_field_round_trips<acquisition::GeometrySettings>();
}

TEST(SettingsJson, ReadersRoundTrip) {
  expect_every_field_round_trips<acquisition::ScanFileSettings>();
}

TEST(SettingsJson, MergeRoundTrips) {
  expect_every_field_round_trips<registration::MergeSettings>();
}

TEST(SettingsJson, RegistrationWithPicksRoundTrips) {
  RegisterCommandSettings settings;
  settings.registration.coarse = registration::CoarseMethod::kPointPairs;
  settings.picks.push_back({2, 1, {{{1.0, 2.0, 3.0}, {4.0, 5.0, 6.5}}}});
  expect_every_field_round_trips(settings);
  const RegisterCommandSettings back =
      settings_from_json<RegisterCommandSettings>(settings_to_json(settings), "test");
  EXPECT_EQ(back.registration.coarse, registration::CoarseMethod::kPointPairs);
  ASSERT_EQ(back.picks.size(), 1u);
  EXPECT_EQ(back.picks[0].pairs[0].target, Eigen::Vector3d(4.0, 5.0, 6.5));
}

// The number of fields of aggregate T: the most initializers T{…} takes
// (each AnyField converts to whatever its field is).
struct AnyField {
  template <typename T>
  operator T() const;  // never called: only asked about
};

template <typename T, typename... Fields>
constexpr std::size_t field_count(Fields... fields) {
  if constexpr (requires { T{fields..., AnyField{}}; }) {
    return field_count<T>(fields..., AnyField{});
  } else {
    return sizeof...(Fields);
  }
}

// Every field of S is in its JSON object `j`, but `threads`.
template <typename S>
void expect_whole(const nlohmann::json& j, const char* what) {
  constexpr bool has_threads = requires(S s) {
    s.threads;
  };
  EXPECT_EQ(j.size() + (has_threads ? 1 : 0), field_count<S>())
      << what << ": a field is missing from modeling/settings_json.cpp";
}

TEST(SettingsJson, EveryFieldOfEveryStructIsWritten) {
  const nlohmann::json geometry =
      nlohmann::json::parse(settings_to_json(acquisition::GeometrySettings{}));
  expect_whole<acquisition::GeometrySettings>(geometry, "GeometrySettings");
  expect_whole<acquisition::RangeNoise>(geometry["range_noise"], "RangeNoise");
  const nlohmann::json readers =
      nlohmann::json::parse(settings_to_json(acquisition::ScanFileSettings{}));
  expect_whole<acquisition::ScanFileSettings>(readers, "ScanFileSettings");
  expect_whole<acquisition::PtxReadSettings>(readers["ptx"], "PtxReadSettings");
  expect_whole<acquisition::LocalOriginSettings>(readers["ptx"]["grid"], "LocalOriginSettings");
  expect_whole<acquisition::SphericalFitSettings>(readers["ptx"]["grid"]["angle_fit"],
                                                  "SphericalFitSettings");
  expect_whole<registration::MergeSettings>(
      nlohmann::json::parse(settings_to_json(registration::MergeSettings{})), "MergeSettings");
  RegisterCommandSettings stage;
  stage.picks.push_back({2, 1, {{}}});
  stage.registration.picks.push_back({1, 0, {{}}});
  const nlohmann::json register_ = nlohmann::json::parse(settings_to_json(stage));
  const nlohmann::json& r = register_["registration"];
  expect_whole<RegisterCommandSettings>(register_, "RegisterCommandSettings");
  expect_whole<ProjectPicks>(register_["picks"][0], "ProjectPicks");
  expect_whole<registration::RegistrationSettings>(r, "RegistrationSettings");
  expect_whole<registration::PickedPairs>(r["picks"][0], "PickedPairs");
  expect_whole<registration::FeatureSettings>(r["features"], "FeatureSettings");
  expect_whole<registration::SampleSettings>(r["features"]["sample"], "SampleSettings");
  expect_whole<registration::HypothesisSettings>(r["features"]["hypotheses"], "HypothesisSettings");
  expect_whole<registration::IcpSettings>(r["icp"], "IcpSettings");
  expect_whole<registration::GlobalSettings>(r["global"], "GlobalSettings");
}

TEST(SettingsJson, ThreadCountsAreNotPartOfTheSettings) {
  acquisition::GeometrySettings settings;
  settings.threads = 7;
  EXPECT_EQ(settings_to_json(settings).find("threads"), std::string::npos);
}

TEST(SettingsJson, MissingKeysTakeDefaultsAndBadValuesAreInputErrors) {
  const auto defaults = settings_from_json<registration::MergeSettings>("{}", "command 3");
  EXPECT_EQ(defaults.range_sigmas, registration::MergeSettings{}.range_sigmas);
  try {
    settings_from_json<registration::MergeSettings>(R"({"range_sigmas": "four"})", "command 3");
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.position().detail, "command 3 settings");
  }
  EXPECT_THROW(settings_from_json<registration::MergeSettings>("[1, 2]", "command 3"),
               core::InputError);
  EXPECT_THROW(settings_from_json<registration::MergeSettings>("{", "command 3"), core::InputError);
}

}  // namespace
}  // namespace scanbench::modeling

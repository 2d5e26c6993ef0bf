// Settings and results as JSON (modeling/command_json): every field written
// is read back, and a user's settings file is read strictly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "acquisition/formats/scan_files.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/command_json.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/import_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "modeling/selection_commands.hpp"
#include "registration/merge.hpp"

namespace scanbench::modeling {
namespace {

using ::testing::HasSubstr;

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

TEST(SettingsJson, ImportRoundTrips) {
  expect_every_field_round_trips<ImportSettings>();
}

TEST(SettingsJson, HarmonizeRoundTrips) {
  expect_every_field_round_trips<HarmonizeCommandSettings>();
}

TEST(SettingsJson, SelectRoundTrips) {
  SelectSettings settings;
  settings.constraints.lasso = {{1.0, 2.0}, {30.0, 2.0}, {30.0, 40.5}};
  settings.constraints.barriers = {{{5.0, 5.0}, {6.0, 7.0}}};
  expect_every_field_round_trips(settings);
  settings.mode = SelectMode::kSubtract;
  settings.grow.channel = segmentation::Channel::kColor;
  const SelectSettings back = settings_from_json<SelectSettings>(settings_to_json(settings), "t");
  EXPECT_EQ(back.mode, SelectMode::kSubtract);
  EXPECT_EQ(back.grow.channel, segmentation::Channel::kColor);
  EXPECT_EQ(back.constraints.lasso, settings.constraints.lasso);
}

TEST(SettingsJson, CommitRoundTripsWithAndWithoutItsGrowSettings) {
  CommitSettings settings;
  settings.scan_id = 4;
  settings.name = "wall";
  settings.parent = 12;
  settings.grow = segmentation::default_grow_settings(segmentation::Channel::kColor);
  expect_every_field_round_trips(settings);
  const CommitSettings back = settings_from_json<CommitSettings>(settings_to_json(settings), "t");
  ASSERT_TRUE(back.grow.has_value());
  EXPECT_EQ(back.grow->channel, segmentation::Channel::kColor);
  EXPECT_EQ(back.parent, std::optional<std::int64_t>(12));
  settings.grow.reset();
  settings.parent.reset();
  const CommitSettings none = settings_from_json<CommitSettings>(settings_to_json(settings), "t");
  EXPECT_FALSE(none.grow.has_value());
  EXPECT_FALSE(none.parent.has_value());
  // A channel alone takes that channel's defaults (a tolerance's unit is the channel's).
  const CommitSettings intensity =
      settings_from_json<CommitSettings>(R"({"grow": {"channel": "intensity"}})", "t");
  ASSERT_TRUE(intensity.grow.has_value());
  EXPECT_EQ(intensity.grow->tolerance,
            segmentation::default_grow_settings(segmentation::Channel::kIntensity).tolerance);
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
  operator T() const {  // never called: only asked about
    std::abort();
  }
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
      << what << ": a field is missing from modeling/command_json.cpp";
}

TEST(SettingsJson, EveryFieldOfEveryStructIsWritten) {
  const nlohmann::json geometry =
      nlohmann::json::parse(settings_to_json(acquisition::GeometrySettings{}));
  expect_whole<acquisition::GeometrySettings>(geometry, "GeometrySettings");
  expect_whole<acquisition::RangeNoise>(geometry["range_noise"], "RangeNoise");
  const nlohmann::json import = nlohmann::json::parse(settings_to_json(ImportSettings{}));
  expect_whole<ImportSettings>(import, "ImportSettings");
  const nlohmann::json& readers = import["readers"];
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
  // Harmonize's object is flat: the pair search's fields beside the solve's.
  const nlohmann::json harmonize =
      nlohmann::json::parse(settings_to_json(HarmonizeCommandSettings{}));
  EXPECT_EQ(harmonize.size() + 2, field_count<registration::ColorPairSettings>() +
                                      field_count<registration::HarmonizeSettings>())
      << "HarmonizeCommandSettings: a field is missing from modeling/command_json.cpp";
  const nlohmann::json select = nlohmann::json::parse(settings_to_json(SelectSettings{}));
  // scan, seed (two fields), mode, the grow settings, lasso, barriers, range noise
  EXPECT_EQ(select.size(), 1 + 1 + 1 + field_count<segmentation::GrowSettings>() +
                               field_count<segmentation::Constraints>() + 1);
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
    EXPECT_EQ(error.file(), "command 3");
    EXPECT_EQ(error.position().detail, "settings");
  }
  // The journal may hold a newer scanbench's keys.
  EXPECT_NO_THROW(settings_from_json<registration::MergeSettings>(R"({"later": 1})", "command 3"));
  EXPECT_THROW(settings_from_json<registration::MergeSettings>("[1, 2]", "command 3"),
               core::InputError);
  EXPECT_THROW(settings_from_json<registration::MergeSettings>("{", "command 3"), core::InputError);
}

// What a user's settings file (SettingsSource::kUser) is refused for: the
// message names the file and the key.
template <typename Settings>
std::string user_refusal(const std::string& json) {
  try {
    settings_from_json<Settings>(json, "s.json", SettingsSource::kUser);
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.file(), "s.json");
    return error.position().detail + ": " + error.problem();
  }
  ADD_FAILURE() << json << " was accepted";
  return "";
}

template <typename Settings>
void expect_journal_settings_read_as_a_user_file(const Settings& settings) {
  const std::string json = settings_to_json(settings);
  const Settings back = settings_from_json<Settings>(json, "s.json", SettingsSource::kUser);
  EXPECT_EQ(settings_to_json(back), json);
}

TEST(SettingsJson, WhatTheJournalStoresReadsBackAsAUserFile) {
  expect_journal_settings_read_as_a_user_file(ImportSettings{});
  expect_journal_settings_read_as_a_user_file(acquisition::GeometrySettings{});
  RegisterCommandSettings picked;
  picked.registration.coarse = registration::CoarseMethod::kPointPairs;
  picked.picks.push_back({2, 1, {{{1.0, 2.0, 3.0}, {4.0, 5.0, 6.5}}}});
  expect_journal_settings_read_as_a_user_file(picked);
  expect_journal_settings_read_as_a_user_file(registration::MergeSettings{});
  HarmonizeCommandSettings matrix;
  matrix.solve.model = registration::ColorModel::kMatrix;
  expect_journal_settings_read_as_a_user_file(matrix);
  expect_journal_settings_read_as_a_user_file(SelectSettings{});
  CommitSettings commit;
  commit.grow = segmentation::default_grow_settings(segmentation::Channel::kRange);
  expect_journal_settings_read_as_a_user_file(commit);
}

TEST(SettingsJson, AUserFileIsRefusedForKeysAndValuesThatDoNotReadBack) {
  using acquisition::GeometrySettings;
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"windw_radius": 3})"),
              HasSubstr("key \"windw_radius\": unknown key"));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"threads": 2})"), HasSubstr("--threads"));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"window_radius": 2.7})"),
              HasSubstr("key \"window_radius\": 2.7 does not fit (it reads as 2)"));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"window_radius": 4294967297})"),
              HasSubstr("key \"window_radius\""));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"range_noise": {"noise_m": 0.01, "x": 1}})"),
              HasSubstr("key \"range_noise.x\": unknown key"));
  EXPECT_THAT(user_refusal<RegisterCommandSettings>(
                  R"({"registration": {"features": {"sample": {"max_points": -3}}}})"),
              HasSubstr("key \"registration.features.sample.max_points\""));
  EXPECT_THAT(user_refusal<RegisterCommandSettings>(R"({"picks": [{"source_id": 2.5}]})"),
              HasSubstr("key \"picks[0].source_id\""));
  EXPECT_THAT(user_refusal<HarmonizeCommandSettings>(R"({"model": "curves"})"),
              HasSubstr("unknown colour model 'curves'"));
  EXPECT_THAT(user_refusal<GeometrySettings>("[1]"), HasSubstr("not an object"));
}

TEST(SettingsJson, AUserFileIsRefusedForValuesOutsideTheirRange) {
  using acquisition::GeometrySettings;
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"window_radius": 0})"),
              HasSubstr("key \"window_radius\": 0 is outside 1 to 127"));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"window_radius": 4, "edge_window_radius": 5})"),
              HasSubstr("key \"edge_window_radius\""));
  EXPECT_THAT(user_refusal<GeometrySettings>(R"({"range_noise": {"noise_m": -1}})"),
              HasSubstr("key \"range_noise.noise_m\""));
  EXPECT_THAT(user_refusal<RegisterCommandSettings>(
                  R"({"registration": {"features": {"similarity": 1.5}}})"),
              HasSubstr("key \"registration.features.similarity\""));
  EXPECT_THAT(user_refusal<RegisterCommandSettings>(
                  R"({"registration": {"global": {"icp": {"loss_scale_m": 0}}}})"),
              HasSubstr("key \"registration.global.icp.loss_scale_m\""));
  EXPECT_THAT(user_refusal<registration::MergeSettings>(R"({"max_normal_angle_deg": 200})"),
              HasSubstr("key \"max_normal_angle_deg\""));
  EXPECT_THAT(user_refusal<HarmonizeCommandSettings>(R"({"stride": 2, "phase": 2})"),
              HasSubstr("key \"phase\""));
  EXPECT_THAT(user_refusal<HarmonizeCommandSettings>(R"({"dark": 200, "bright": 100})"),
              HasSubstr("key \"bright\""));
}

}  // namespace
}  // namespace scanbench::modeling

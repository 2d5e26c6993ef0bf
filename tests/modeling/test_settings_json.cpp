// Settings as whole structs in JSON: every field written is read back.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "acquisition/scan_files.hpp"
#include "acquisition/scan_geometry.hpp"
#include "core/errors.hpp"
#include "modeling/registration_stage.hpp"
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
  RegisterStageSettings settings;
  settings.registration.coarse = registration::CoarseMethod::kPointPairs;
  settings.picks.push_back({2, 1, {{{1.0, 2.0, 3.0}, {4.0, 5.0, 6.5}}}});
  expect_every_field_round_trips(settings);
  const RegisterStageSettings back =
      settings_from_json<RegisterStageSettings>(settings_to_json(settings), "test");
  EXPECT_EQ(back.registration.coarse, registration::CoarseMethod::kPointPairs);
  ASSERT_EQ(back.picks.size(), 1u);
  EXPECT_EQ(back.picks[0].pairs[0].target, Eigen::Vector3d(4.0, 5.0, 6.5));
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

// JSON input files read one way: a syntax error or a number too large for a
// double names the file, line and byte; whole numbers are never wrapped or
// truncated; unknown keys are named.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <limits>

#include "acquisition/camera_view.hpp"
#include "acquisition/formats/json_input.hpp"
#include "core/errors.hpp"
#include "support/test_support.hpp"

namespace scanbench::acquisition {
namespace {

using nlohmann::json;
using test::ScratchDir;
using ::testing::HasSubstr;

core::InputError refusal(const std::function<void()>& read) {
  try {
    read();
  } catch (const core::InputError& error) {
    return error;
  }
  ADD_FAILURE() << "was not refused";
  return core::InputError("", {}, "");
}

TEST(JsonInput, ANumberTooLargeForADoubleIsNamedWithItsLineAndByte) {
  const core::InputError error =
      refusal([] { parse_json("{\"width\": 64,\n \"x\": 1e400}", "view.json"); });
  EXPECT_EQ(error.file(), "view.json");
  EXPECT_EQ(error.position().line, 2u);
  EXPECT_THAT(error.problem(), HasSubstr("not finite (too large for a double): 1e400"));
  const core::InputError syntax = refusal([] { parse_json("{\"ops\": [", "s.json"); });
  EXPECT_THAT(syntax.problem(), HasSubstr("not valid JSON"));
  EXPECT_EQ(syntax.position().line, 1u);
}

TEST(JsonInput, WholeNumbersAreNeverWrappedOrTruncated) {
  const JsonPlace place{"f.json", "key \"width\""};
  EXPECT_EQ(whole_number(json::parse("640"), 1, 16384, place, "width"), 640);
  EXPECT_EQ(whole_number(json::parse("640.0"), 1, 16384, place, "width"), 640);
  for (const char* bad :
       {"4294967297", "2.7", "-1", "18446744073709551615", "\"7\"", "1e300", "null"}) {
    const core::InputError error =
        refusal([&] { whole_number(json::parse(bad), 1, 16384, place, "width"); });
    EXPECT_THAT(error.what(), HasSubstr("width must be a whole number from 1 to 16384")) << bad;
    EXPECT_THAT(error.what(), HasSubstr("f.json: key \"width\"")) << bad;
  }
  // 2^63 as a double: beyond any int64, whatever the upper bound.
  EXPECT_THROW(whole_number(json::parse("9223372036854775807.0"), 1,
                            std::numeric_limits<std::int64_t>::max(), place, "id"),
               core::InputError);
  EXPECT_THROW(finite_number(json::parse("1e308"), -1e8, 1e8, place, "x"), core::InputError);
  EXPECT_THROW(refuse_unknown_keys(json::parse(R"({"widht": 3})"), {"width"}, place),
               core::InputError);
}

class BadViewFile : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST_P(BadViewFile, IsRefusedNamingTheFileAndTheKey) {
  const ScratchDir dir;
  const std::filesystem::path file = dir / "view.json";
  std::ofstream(file) << GetParam().first;
  const core::InputError error = refusal([&] { read_camera_view(file); });
  EXPECT_EQ(error.file(), file.string());
  EXPECT_THAT(error.what(), HasSubstr(GetParam().second)) << GetParam().first;
}

INSTANTIATE_TEST_SUITE_P(
    ViewFiles, BadViewFile,
    ::testing::Values(
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60,
                      "position": [1e308, 0, 0], "look_at": [0, 0, 0]})",
                  "key \"position\": each coordinate must be a finite number"},
        std::pair{R"({"width": 4294967297, "height": 48, "vertical_fov_deg": 60,
                      "position": [1, 0, 0], "look_at": [0, 0, 0]})",
                  "the width must be a whole number from 1 to 16384"},
        std::pair{R"({"width": 2.7, "height": 48, "vertical_fov_deg": 60,
                      "position": [1, 0, 0], "look_at": [0, 0, 0]})",
                  "the width must be a whole number"},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 1e400,
                      "position": [1, 0, 0], "look_at": [0, 0, 0]})",
                  "holds a number that is not finite"},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60, "postion": [1, 0, 0],
                      "look_at": [0, 0, 0]})",
                  "unknown key \"postion\""},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60,
                      "T_world_camera": [1, 0, 0, 1e9, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]})",
                  "each element must be a finite number"}));

// A camera path: a view file's optics, then its poses, each refused by its
// frame's place.
class BadPathFile : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

TEST(CameraPath, ReadsEveryFrameWithTheSharedOptics) {
  const ScratchDir dir;
  const std::filesystem::path file = dir / "path.json";
  std::ofstream(file) << R"({"width": 64, "height": 48, "vertical_fov_deg": 50, "frames": [
      {"position": [0, 0, 1], "look_at": [5, 0, 1]},
      {"T_world_camera": [1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 3, 0, 0, 0, 1]}]})";
  const std::vector<CameraView> path = read_camera_path(file);
  ASSERT_EQ(path.size(), 2u);
  EXPECT_EQ(path[1].width, 64);
  EXPECT_EQ(path[1].vertical_fov_deg, 50.0);
  EXPECT_TRUE(path[0].T_world_camera.isApprox(look_at({0, 0, 1}, {5, 0, 1})));
  EXPECT_EQ(path[1].T_world_camera.translation(), Eigen::Vector3d(2, 0, 3));
}

TEST_P(BadPathFile, IsRefusedNamingTheFileTheFrameAndTheKey) {
  const ScratchDir dir;
  const std::filesystem::path file = dir / "path.json";
  std::ofstream(file) << GetParam().first;
  const core::InputError error = refusal([&] { read_camera_path(file); });
  EXPECT_EQ(error.file(), file.string());
  EXPECT_THAT(error.what(), HasSubstr(GetParam().second)) << GetParam().first;
}

INSTANTIATE_TEST_SUITE_P(
    PathFiles, BadPathFile,
    ::testing::Values(
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60, "frames": []})",
                  "key \"frames\": must be an array of 1 to 1 000 000 camera poses"},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60, "frames": [
                      {"position": [1, 0, 0], "look_at": [0, 0, 0]},
                      {"position": [1, 0, 0], "look_at": [1, 0, 0]}]})",
                  "key \"frames[1].look_at\": equals the position"},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60, "frames": [
                      {"position": [1, 0, 0], "look": [0, 0, 0]}]})",
                  "unknown key \"look\""},
        std::pair{R"({"width": 64, "vertical_fov_deg": 60, "frames": [
                      {"position": [1, 0, 0], "look_at": [0, 0, 0]}]})",
                  "key \"height\": is missing"},
        std::pair{R"({"width": 64, "height": 48, "vertical_fov_deg": 60, "frames": [7]})",
                  "key \"frames[0]\": must be a JSON object"}));

}  // namespace
}  // namespace scanbench::acquisition

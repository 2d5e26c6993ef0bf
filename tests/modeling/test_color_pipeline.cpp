// Colour spaces and the colour edit model: conversions round-trip, each
// parameter does what it says in L*a*b*, children inherit what they do not
// set, and edits round-trip through JSON.
#include <gtest/gtest.h>

#include <random>

#include "acquisition/color_space.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/store/project.hpp"

namespace scanbench::modeling {
namespace {

TEST(ColorSpace, EightBitColoursSurviveTheRoundTripThroughLab) {
  for (int v = 0; v < 256; ++v) {
    const auto grey = static_cast<std::uint8_t>(v);
    const Eigen::Vector3d lab = acquisition::srgb_to_lab({grey, grey, grey});
    EXPECT_NEAR(lab.y(), 0.0, 1e-9);
    EXPECT_NEAR(lab.z(), 0.0, 1e-9);
    EXPECT_EQ(acquisition::lab_to_srgb(lab), (std::array<std::uint8_t, 3>{grey, grey, grey}));
  }
  EXPECT_NEAR(acquisition::srgb_to_lab({255, 255, 255}).x(), 100.0, 1e-9);
  const Eigen::Vector3d red = acquisition::srgb_to_lab({255, 0, 0});  // L 53.24, a 80.09, b 67.20
  EXPECT_NEAR(red.x(), 53.24, 0.01);
  EXPECT_NEAR(red.y(), 80.09, 0.02);
  EXPECT_NEAR(red.z(), 67.20, 0.02);
  std::mt19937 random(7);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int k = 0; k < 2000; ++k) {
    const std::array<std::uint8_t, 3> c = {static_cast<std::uint8_t>(byte(random)),
                                           static_cast<std::uint8_t>(byte(random)),
                                           static_cast<std::uint8_t>(byte(random))};
    EXPECT_EQ(acquisition::lab_to_srgb(acquisition::srgb_to_lab(c)), c);
  }
}

TEST(ColorEdit, EachParameterActsInLab) {
  const Eigen::Vector3d lab(40.0, 20.0, -10.0);
  EXPECT_EQ(apply(ResolvedColorEdit{}, lab), lab);
  ResolvedColorEdit brighter;
  brighter.brightness = 15.0;
  EXPECT_EQ(apply(brighter, lab), Eigen::Vector3d(55.0, 20.0, -10.0));
  ResolvedColorEdit contrast;
  contrast.contrast = 2.0;
  EXPECT_EQ(apply(contrast, lab), Eigen::Vector3d(30.0, 20.0, -10.0));  // 50 + 2 · (40 − 50)
  ResolvedColorEdit gamma;
  gamma.gamma = 2.0;
  EXPECT_NEAR(apply(gamma, lab).x(), 100.0 * std::sqrt(0.4), 1e-9);
  ResolvedColorEdit hue;
  hue.hue_deg = 180.0;
  EXPECT_TRUE(apply(hue, lab).isApprox(Eigen::Vector3d(40.0, -20.0, 10.0), 1e-12));
  ResolvedColorEdit grey;
  grey.saturation = 0.0;
  EXPECT_EQ(apply(grey, lab), Eigen::Vector3d(40.0, 0.0, 0.0));
  ResolvedColorEdit transfer;
  transfer.transfer = {{1.0, 0.5, 0.5}, {10.0, 1.0, 2.0}};
  EXPECT_EQ(apply(transfer, lab), Eigen::Vector3d(50.0, 11.0, -3.0));
}

// Gamma, then contrast, then brightness: L* 16 → 40 → 30 → 35 (contrast
// first would give 50 + 2 · (16 − 50) < 0, clamped, and another result).
TEST(ColorEdit, LightnessStepsApplyInTheirOrder) {
  ResolvedColorEdit edit;
  edit.gamma = 2.0;
  edit.contrast = 2.0;
  edit.brightness = 5.0;
  EXPECT_NEAR(apply(edit, Eigen::Vector3d(16.0, 0.0, 0.0)).x(), 35.0, 1e-9);
}

TEST(ColorEdit, ChildrenInheritWhatTheyDoNotSet) {
  std::vector<store::ObjectNode> nodes(3);
  nodes[0].id = 1;
  nodes[0].kind = store::NodeKind::kGroup;
  nodes[0].color.brightness = 10.0;
  nodes[0].color.saturation = 0.5;
  nodes[1].id = 2;
  nodes[1].parent = 1;
  nodes[1].color.hue_deg = 30.0;
  nodes[2].id = 3;
  nodes[2].parent = 1;
  nodes[2].color.brightness = -5.0;  // overrides the group's
  // Children listed before their parent resolve all the same.
  std::swap(nodes[0], nodes[2]);
  const std::map<std::int64_t, ResolvedColorEdit> resolved = resolve_color_edits(nodes);
  EXPECT_EQ(resolved.at(1).brightness, 10.0);
  EXPECT_EQ(resolved.at(2).brightness, 10.0);
  EXPECT_EQ(resolved.at(2).hue_deg, 30.0);
  EXPECT_EQ(resolved.at(2).saturation, 0.5);
  EXPECT_EQ(resolved.at(3).brightness, -5.0);
  EXPECT_EQ(resolved.at(3).saturation, 0.5);
  EXPECT_EQ(resolved.at(3).hue_deg, 0.0);
}

TEST(ColorEdit, EditsAndCorrectionsRoundTripThroughJson) {
  store::ColorEdit edit;
  edit.gamma = 1.25;
  edit.hue_deg = -0.0;
  edit.transfer = store::LabTransfer{{1.0, 0.0, 2.5}, {-3.0, 0.125, 7.0}};
  EXPECT_EQ(store::color_edit_from_json(to_json(edit)), edit);
  EXPECT_EQ(to_json(store::ColorEdit{}), "");
  EXPECT_TRUE(store::color_edit_from_json("").empty());
  store::ScanColorCorrection correction;
  correction.matrix << 1.1, 0.01, 0.0, -0.02, 0.9, 0.0, 0.0, 0.0, 1.3;
  correction.offset = {0.001, -0.002, 0.0};
  EXPECT_EQ(store::scan_color_correction_from_json(store::to_json(correction)), correction);
  EXPECT_THROW(store::color_edit_from_json("{\"contrast\": -1}"), std::invalid_argument);
  EXPECT_THROW(store::color_edit_from_json("{\"brightness\": \"a lot\"}"), std::invalid_argument);
  EXPECT_THROW(store::color_edit_from_json("[1, 2]"), std::invalid_argument);
  EXPECT_THROW(
      store::scan_color_correction_from_json("{\"matrix\": [[1, 0, 0]], \"offset\": [0, 0, 0]}"),
      std::invalid_argument);
}

TEST(ColorPipeline, ColoursWithoutEditsPassBitExactly) {
  store::ScanColorCorrection double_red;
  double_red.matrix(0, 0) = 2.0;
  ResolvedColorEdit grey;
  grey.saturation = 0.0;
  const ColorPipeline pipeline({{2, double_red}, {3, store::ScanColorCorrection{}}},
                               {{5, grey}, {6, ResolvedColorEdit{}}});
  const std::array<std::uint8_t, 3> c = {120, 80, 40};
  EXPECT_EQ(pipeline.shown(1, 0, c), c);
  EXPECT_EQ(pipeline.shown(3, 6, c), c);
  const auto red = pipeline.shown(2, 0, c);
  EXPECT_GT(red[0], c[0]);
  EXPECT_EQ(red[1], c[1]);
  EXPECT_EQ(red[2], c[2]);
  const auto neutral = pipeline.shown(1, 5, c);
  EXPECT_NEAR(neutral[0], neutral[1], 1);
  EXPECT_NEAR(neutral[1], neutral[2], 1);
}

}  // namespace
}  // namespace scanbench::modeling

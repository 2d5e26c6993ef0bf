// Measurements (modeling/measurements): their values, kept in the project
// through the journal (undo brings the earlier list back), refused whole
// when one is malformed, and written as CSV.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "modeling/measurements.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using ::testing::HasSubstr;

Measurement make(MeasureKind kind, std::vector<Eigen::Vector3d> points, std::string name = "m") {
  return {std::move(name), kind, std::move(points)};
}

// Far from the origin, as georeferenced coordinates are (UTM-like).
const Eigen::Vector3d kAt(640000.0, 8500000.0, 120.0);

TEST(Measurements, EachKindMeasuresWhatItSays) {
  EXPECT_DOUBLE_EQ(measured_value(make(MeasureKind::kPoint, {kAt})), 120.0);
  EXPECT_NEAR(
      measured_value(make(MeasureKind::kDistance, {kAt, kAt + Eigen::Vector3d(3.0, 4.0, 0.0)})),
      5.0, 1e-9);
  EXPECT_NEAR(
      measured_value(make(MeasureKind::kDistance, {kAt, kAt + Eigen::Vector3d(0.001, 0, 0)})),
      0.001, 1e-9);  // a millimetre, 8 500 km from the origin
  EXPECT_NEAR(
      measured_value(make(MeasureKind::kHeight, {kAt, kAt + Eigen::Vector3d(5.0, 1.0, -2.5)})),
      -2.5, 1e-9);
  EXPECT_NEAR(measured_value(make(MeasureKind::kAngle, {kAt + Eigen::Vector3d::UnitX(), kAt,
                                                        kAt + Eigen::Vector3d::UnitY()})),
              90.0, 1e-9);
  // A 2 m × 3 m rectangle on a wall leaning 30° back: 6 m².
  const Eigen::Vector3d along(1.0, 0.0, 0.0);
  const Eigen::Vector3d up(0.0, std::sin(0.5236), std::cos(0.5236));
  EXPECT_NEAR(measured_value(make(MeasureKind::kArea,
                                  {kAt, kAt + 2.0 * along, kAt + 2.0 * along + 3.0 * up,
                                   kAt + 3.0 * up})),
              6.0, 1e-6);
}

TEST(Measurements, TheProjectKeepsTheListAndUndoBringsTheEarlierOneBack) {
  const test::ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  EXPECT_TRUE(load_measurements(project).empty());
  const std::vector<Measurement> one = {
      make(MeasureKind::kDistance, {kAt, kAt + Eigen::Vector3d(1.0, 2.0, 3.0)}, "door width")};
  save_measurements(project, one, "add distance", project.revision());
  std::vector<Measurement> two = one;
  two.push_back(make(MeasureKind::kPoint, {kAt}, "benchmark"));
  save_measurements(project, two, "add point", project.revision());
  ASSERT_EQ(load_measurements(project).size(), 2u);
  EXPECT_EQ(load_measurements(project)[1].name, "benchmark");
  EXPECT_EQ(load_measurements(project)[0].points[1], kAt + Eigen::Vector3d(1.0, 2.0, 3.0));
  project.undo();
  ASSERT_EQ(load_measurements(project).size(), 1u);
  EXPECT_EQ(load_measurements(project)[0].name, "door width");
  // A malformed one refuses the whole list, and nothing is written.
  const std::size_t journal = project.history().size();
  try {
    save_measurements(project, {make(MeasureKind::kAngle, {kAt, kAt})}, "add angle",
                      project.revision());
    ADD_FAILURE() << "an angle of two points was accepted";
  } catch (const core::InputError& e) {
    EXPECT_THAT(e.problem(), HasSubstr("angle takes 3 points, not 2"));
  }
  EXPECT_EQ(project.history().size(), journal);
  EXPECT_EQ(load_measurements(project).size(), 1u);
}

TEST(Measurements, CsvHoldsEveryPointAtFullPrecision) {
  const std::string csv =
      measurements_csv({make(MeasureKind::kPoint, {kAt}, "a \"quoted\" name"),
                        make(MeasureKind::kDistance, {kAt, kAt + Eigen::Vector3d(0.001, 0, 0)})});
  EXPECT_THAT(csv, HasSubstr("name,kind,value,unit,x1,y1,z1,x2,y2,z2\n"));
  EXPECT_THAT(csv, HasSubstr("\"a \"\"quoted\"\" name\",point,120,m,640000,8500000,120\n"));
  EXPECT_THAT(csv, HasSubstr(",distance,0.00100000"));
  EXPECT_THAT(csv, HasSubstr(",640000.001,8500000,120\n"));
}

}  // namespace
}  // namespace scanbench::modeling

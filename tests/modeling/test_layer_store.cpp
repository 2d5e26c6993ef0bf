// The per-pixel layer store: typed round trips, versions, removal, damage.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "core/errors.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"
#include "project_test_support.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;
using ::testing::HasSubstr;

acquisition::ScanGeometry made_up_geometry(std::size_t n) {
  acquisition::ScanGeometry g;
  for (std::size_t i = 0; i < n; ++i) {
    g.footprint_m.push_back(0.01f * static_cast<float>(i));
    g.normal.emplace_back(0.0f, -1.0f, static_cast<float>(i) * -0.0f);
    g.confidence.push_back(i % 2 ? 0.5f : 0.0f);
    g.flags.push_back(static_cast<std::uint8_t>(i % 4));
  }
  return g;
}

// Writes `layers` to scan `id` as one command.
void put_committed(store::Project& project, std::int64_t id,
                   const std::vector<store::EncodedLayer>& layers) {
  store::Project::Edit edit = project.begin_command("test", "{}");
  for (const store::EncodedLayer& layer : layers) project.put_layer(edit, id, layer);
  edit.commit("{}");
}

TEST(Layers, GeometryRoundTripsBitForBit) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const acquisition::Scan scan = test::tiny_scan(true, true, true, 3, 4);
  const std::int64_t id = test::insert_committed(project, scan);
  EXPECT_FALSE(store::load_geometry(project, id).has_value());
  const acquisition::ScanGeometry geometry = made_up_geometry(scan.pixel_count());
  put_committed(project, id, store::encode_geometry(geometry));
  const std::optional<acquisition::ScanGeometry> back =
      store::load_geometry(store::Project::open(dir / "p.sbproj"), id);
  ASSERT_TRUE(back.has_value());
  EXPECT_TRUE(test::same_bytes(back->footprint_m, geometry.footprint_m));
  EXPECT_TRUE(test::same_bytes(back->normal, geometry.normal));
  EXPECT_TRUE(test::same_bytes(back->confidence, geometry.confidence));
  EXPECT_TRUE(test::same_bytes(back->flags, geometry.flags));
}

TEST(Layers, ANewLayerNeedsNoSchemaChangeAndTheNewestVersionWins) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t id = test::insert_committed(project, test::tiny_scan(true, false, false));
  const std::vector<std::uint32_t> first = {7, 0, 0, 7, 1, 2};
  const std::vector<std::uint32_t> second = {1, 1, 1, 0, 0, 0};
  put_committed(
      project, id,
      {store::encode_layer<std::uint32_t>("membership", store::ElementType::kU32, first)});
  put_committed(
      project, id,
      {store::encode_layer<std::uint32_t>("membership", store::ElementType::kU32, second)});
  EXPECT_EQ(project.load_layer<std::uint32_t>(id, "membership", store::ElementType::kU32), second);
  EXPECT_THAT(project.layer_names(id), ::testing::Contains("membership"));
  project.undo();
  EXPECT_EQ(project.load_layer<std::uint32_t>(id, "membership", store::ElementType::kU32), first);
}

TEST(Layers, RemovingALayerHidesItUntilUndone) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t id = test::insert_committed(project, test::tiny_scan(true, false, false));
  const std::vector<std::uint8_t> keep = {1, 0, 1, 1, 0, 0};
  put_committed(
      project, id,
      {store::encode_layer<std::uint8_t>(store::layer::kKeep, store::ElementType::kU8, keep)});
  {
    store::Project::Edit edit = project.begin_command("test", "{}");
    project.remove_layer(edit, id, store::layer::kKeep);
    project.remove_layer(edit, id, "never stored");  // no effect
    edit.commit("{}");
  }
  EXPECT_FALSE(store::load_keep_mask(project, id).has_value());
  EXPECT_THAT(project.layer_names(id), ::testing::Not(::testing::Contains("keep")));
  project.undo();
  EXPECT_EQ(store::load_keep_mask(project, id), keep);
}

TEST(Layers, AWrongTypeOrSizeIsReportedAsDamage) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  std::int64_t id = 0;
  {
    store::Project project = store::Project::create(file);
    id = test::insert_committed(project, test::tiny_scan(true, false, false));
    const std::vector<float> values(6, 1.0f);
    put_committed(project, id,
                  {store::encode_layer<float>("weights", store::ElementType::kF32, values)});
  }
  const store::Project project = store::Project::open(file);
  try {
    project.load_layer<std::uint8_t>(id, "weights", store::ElementType::kU8);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_EQ(error.position().detail, "scan " + std::to_string(id) + ", layer weights");
    EXPECT_THAT(error.problem(), HasSubstr("holds f32 elements, expected u8"));
  }
  test::RawDatabase(file).execute(
      "UPDATE scan_layers SET element_count = 5 WHERE name = 'weights'");
  EXPECT_THROW(
      store::Project::open(file).load_layer<float>(id, "weights", store::ElementType::kF32),
      core::InputError);
}

TEST(Layers, PartialGeometryIsDamage) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const std::int64_t id = test::insert_committed(project, test::tiny_scan(true, false, false));
  std::vector<store::EncodedLayer> layers = store::encode_geometry(made_up_geometry(6));
  layers.pop_back();
  put_committed(project, id, layers);
  EXPECT_THROW(store::load_geometry(project, id), core::InputError);
}

TEST(Poses, SetPoseMovesPoseScannerAndBoundsAndKeepsTheOldPose) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  acquisition::Scan scan = test::tiny_scan(true, false, false, 3, 4);
  const Eigen::Isometry3d before = scan.T_world_scan;
  const std::int64_t id = test::insert_committed(project, scan);
  {
    store::Project::Edit edit = project.begin_command("register", "{}");
    scan.T_world_scan.translation() += Eigen::Vector3d(10.0, -2.0, 0.5);
    project.set_pose(edit, id, scan);
    edit.commit("{}");
  }
  store::StoredScanSummary stored = store::Project::open(dir / "p.sbproj").scans().at(0);
  EXPECT_TRUE(stored.summary.T_world_scan.isApprox(scan.T_world_scan));
  // The scanner moved with the scan: its place in the scan frame is the same.
  const Eigen::Vector3d scanner_scan =
      before.inverse() * test::tiny_scan(true, false, false, 3, 4).scanner.position_world;
  EXPECT_TRUE(stored.summary.scanner.position_world.isApprox(scan.T_world_scan * scanner_scan));
  const std::optional<Eigen::AlignedBox3d> bounds = acquisition::world_bounds(scan);
  ASSERT_TRUE(bounds && stored.summary.bbox_world);
  EXPECT_TRUE(stored.summary.bbox_world->isApprox(*bounds));
  project.undo();
  stored = project.scans().at(0);
  EXPECT_TRUE(test::same_bytes(Eigen::Matrix4d(stored.summary.T_world_scan.matrix()),
                               Eigen::Matrix4d(before.matrix())));
}

// Values that compress poorly (so a layer spans several of the reader's and
// writer's pieces of 1 MB) with runs that compress well.
std::vector<Eigen::Vector3f> noisy_vectors(std::size_t n) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> value(-1.0f, 1.0f);
  std::vector<Eigen::Vector3f> values(n);
  for (std::size_t i = 0; i < n; ++i) {
    values[i] = i % 5 == 0 ? Eigen::Vector3f::Zero()
                           : Eigen::Vector3f(value(random), value(random), value(random));
  }
  return values;
}

// Reads a layer back in bands of the given heights, in turn, until its end.
std::vector<Eigen::Vector3f> read_in_bands(store::LayerRowReader reader,
                                           const std::vector<int>& heights) {
  std::vector<Eigen::Vector3f> values;
  for (std::size_t k = 0; reader.rows_read() < reader.rows(); ++k) {
    const int rows = std::min(heights[k % heights.size()], reader.rows() - reader.rows_read());
    std::vector<Eigen::Vector3f> band(static_cast<std::size_t>(rows) * reader.columns());
    reader.read(std::span(band));
    values.insert(values.end(), band.begin(), band.end());
  }
  return values;
}

TEST(LayerRows, ALayerStoredWholeReadsInAnyBandsOfRows) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const acquisition::Scan scan = test::tiny_scan(true, false, false, 301, 700);
  const std::int64_t id = test::insert_committed(project, scan);
  const std::vector<Eigen::Vector3f> normals = noisy_vectors(scan.pixel_count());
  put_committed(project, id,
                {store::encode_layer<Eigen::Vector3f>(store::layer::kNormal,
                                                      store::ElementType::kF32x3, normals)});
  for (const std::vector<int>& heights : {std::vector<int>{301}, {1}, {17, 100, 3}}) {
    auto reader = project.open_layer_rows(id, store::layer::kNormal, store::ElementType::kF32x3);
    ASSERT_TRUE(reader.has_value());
    EXPECT_EQ(reader->rows(), 301);
    EXPECT_EQ(reader->columns(), 700);
    EXPECT_TRUE(test::same_bytes(read_in_bands(std::move(*reader), heights), normals));
  }
  EXPECT_FALSE(project.open_layer_rows(id, store::layer::kKeep, store::ElementType::kU8));
  // Checked as load_layer checks it, before anything is decoded.
  try {
    project.open_layer_rows(id, store::layer::kNormal, store::ElementType::kF32);
    FAIL() << "expected core::InputError";
  } catch (const core::InputError& error) {
    EXPECT_THAT(error.problem(), HasSubstr("holds f32x3 elements, expected f32"));
  }
}

TEST(LayerRows, ALayerWrittenByRowsIsTheLayerStoredWhole) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const acquisition::Scan scan = test::tiny_scan(true, false, false, 301, 700);
  const std::int64_t id = test::insert_committed(project, scan);
  const std::vector<Eigen::Vector3f> normals = noisy_vectors(scan.pixel_count());
  store::LayerRowWriter writer(store::layer::kNormal, store::ElementType::kF32x3, 301, 700);
  for (int row = 0; row < 301;) {
    const int rows = std::min(row % 3 == 0 ? 50 : 1, 301 - row);
    writer.write(std::span(normals).subspan(static_cast<std::size_t>(row) * 700,
                                            static_cast<std::size_t>(rows) * 700));
    row += rows;
  }
  ASSERT_TRUE(writer.complete());
  {
    store::Project::Edit edit = project.begin_command("test", "{}");
    project.put_layer(edit, id, writer);
    edit.commit("{}");
  }
  {
    const store::Project reopened = store::Project::open(dir / "p.sbproj");
    EXPECT_TRUE(test::same_bytes(*reopened.load_layer<Eigen::Vector3f>(id, store::layer::kNormal,
                                                                       store::ElementType::kF32x3),
                                 normals));
    EXPECT_TRUE(reopened.check().damage.empty());
  }
  // Its frame is in the column `frame` (schema 10), where damage is found too.
  test::RawDatabase(dir / "p.sbproj")
      .execute(
          "UPDATE scan_layers SET frame = substr(frame, 1, 5000) || x'00' || "
          "substr(frame, 5002) WHERE name = 'normal' AND length(data) = 0");
  const store::Project damaged = store::Project::open(dir / "p.sbproj");
  const store::Project::CheckReport report = damaged.check();
  ASSERT_EQ(report.damage.size(), 1u);
  EXPECT_THAT(report.damage[0], HasSubstr("layer normal"));
  EXPECT_THROW(
      damaged.load_layer<Eigen::Vector3f>(id, store::layer::kNormal, store::ElementType::kF32x3),
      core::InputError);
}

// Reads every row of layer `name` of scan `id` in bands of 10 rows.
void read_every_row(const store::Project& project, std::int64_t id, const char* name) {
  auto reader = project.open_layer_rows(id, name, store::ElementType::kF32);
  ASSERT_TRUE(reader.has_value());
  std::vector<float> band(static_cast<std::size_t>(reader->columns()) * 10);
  while (reader->rows_read() < reader->rows()) {
    const int rows = std::min(10, reader->rows() - reader->rows_read());
    reader->read(std::span(band).first(static_cast<std::size_t>(rows) * reader->columns()));
  }
}

TEST(LayerRows, DamageIsFoundWhereverItIs) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  std::int64_t id = 0;
  {
    store::Project project = store::Project::create(file);
    id = test::insert_committed(project, test::tiny_scan(true, false, false, 200, 300));
    std::vector<float> weights(200 * 300);
    for (std::size_t i = 0; i < weights.size(); ++i) weights[i] = std::sin(0.001f * i);
    put_committed(project, id,
                  {store::encode_layer<float>("weights", store::ElementType::kF32, weights)});
  }
  test::RawDatabase(file).execute(
      "CREATE TABLE intact AS SELECT data FROM scan_layers WHERE name = 'weights'");
  // Changes the layer's data by `change` (SQL of the column `data`), expects
  // `problem` when its rows are read, and puts the intact data back.
  const auto expect_damage = [&](const std::string& change, const char* problem) {
    SCOPED_TRACE(change);
    test::RawDatabase(file).execute("UPDATE scan_layers SET data = " + change +
                                    " WHERE name = 'weights'");
    try {
      read_every_row(store::Project::open(file), id, "weights");
      ADD_FAILURE() << "expected core::InputError";
    } catch (const core::InputError& error) {
      EXPECT_EQ(error.position().detail, "scan " + std::to_string(id) + ", layer weights");
      EXPECT_THAT(error.problem(), HasSubstr(problem));
    }
    test::RawDatabase(file).execute(
        "UPDATE scan_layers SET data = (SELECT data FROM intact) WHERE name = 'weights'");
  };
  read_every_row(store::Project::open(file), id, "weights");  // intact
  expect_damage("substr(data, 1, length(data) - 40)", "damaged channel data");
  expect_damage("data || x'00'", "bytes follow the frame");
  expect_damage("substr(data, 1, 9000) || x'5a' || substr(data, 9002)", "damaged channel data");
  expect_damage("x'0102'", "not a zstd frame");
}

}  // namespace
}  // namespace scanbench::modeling

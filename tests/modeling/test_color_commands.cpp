// The colour commands on a project: an edit changes only its own object's
// shown colours and never the scans', undo restores them bit for bit, edits
// and corrections survive reopening, clones match their source, and
// harmonize recovers gains applied to a copy of a scan.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "acquisition/color_space.hpp"
#include "acquisition/formats/ptx_reader.hpp"
#include "acquisition/geometry/scan_geometry.hpp"
#include "core/errors.hpp"
#include "core/progress.hpp"
#include "modeling/color_commands.hpp"
#include "modeling/color_pipeline.hpp"
#include "modeling/export_command.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "modeling/selection_tools.hpp"
#include "modeling/store/typed_layers.hpp"
#include "modeling/tree_commands.hpp"
#include "room_project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;

// The room with its floor and the wall ahead as objects, both in the group
// "room".
struct RoomObjects {
  std::int64_t scan = 0;
  std::int64_t room = 0;
  std::int64_t floor = 0;
  std::int64_t wall = 0;
};

RoomObjects segment_room(store::Project& project) {
  SelectionTools tools;  // the selections: session state
  RoomObjects out;
  out.scan = store_room(project);
  out.room = group_nodes(project, {"room", std::nullopt, {}}).node_id;
  tools.select(project, select_at(out.scan, 0, -45));
  out.floor = tools.commit(project, {out.scan, "floor", out.room}).node_id;
  tools.select(project, select_at(out.scan, -20, 0));
  out.wall = tools.commit(project, {out.scan, "wall", out.room}).node_id;
  return out;
}

// The model's colours as it shows them, point by point, scan after scan
// in pixel order (the same project state gives the same order): each
// scan's in-model points but those the segmentation deleted, through the
// CPU's colour pipeline (modeling/color_pipeline.hpp), which the
// renderer's shaders follow, with each point's owner.
using Colours = std::vector<std::array<std::uint8_t, 4>>;
struct ShownModel {
  struct Points {
    Colours rgba;
    std::vector<std::uint32_t> node;
    std::size_t size() const { return rgba.size(); }
  } points;
};

ShownModel model_of(const store::Project& project) {
  const modeling::ColorPipeline pipeline(project.scan_color_corrections(),
                                         modeling::resolve_color_edits(project.object_nodes()));
  ShownModel model;
  for (const store::StoredScanSummary& stored : project.scans()) {
    const acquisition::Scan scan = project.load_scan(stored.id);
    const std::optional<acquisition::ScanGeometry> geometry =
        store::load_geometry(project, stored.id);
    const auto membership = project.load_layer<std::uint32_t>(stored.id, store::layer::kMembership,
                                                              store::ElementType::kU32);
    for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
      if (!geometry || !acquisition::in_model(scan, *geometry, i)) continue;
      const std::uint32_t owner = membership ? (*membership)[i] : 0;
      if (owner == store::kDeletedPoints) continue;
      const std::array<std::uint8_t, 3> rgb = pipeline.shown(
          stored.id, owner, {scan.rgb[3 * i], scan.rgb[3 * i + 1], scan.rgb[3 * i + 2]});
      model.points.rgba.push_back({rgb[0], rgb[1], rgb[2], 255});
      model.points.node.push_back(owner);
    }
  }
  return model;
}

Eigen::Vector3d mean_lab(const ShownModel& model, std::uint32_t node) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    if (model.points.node[k] != node) continue;
    const auto& c = model.points.rgba[k];
    sum += acquisition::srgb_to_lab({c[0], c[1], c[2]});
    ++n;
  }
  return sum / static_cast<double>(std::max<std::size_t>(n, 1));
}

TEST(Recolor, AnEditChangesOnlyItsObjectAndUndoRestoresItBitExactly) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const RoomObjects room = segment_room(project);
  const ShownModel before = model_of(project);
  const acquisition::Scan scan_before = project.load_scan(room.scan);

  RecolorSettings settings;
  settings.node = room.wall;
  settings.set.hue_deg = 120.0;
  settings.set.brightness = -10.0;
  recolor_object(project, settings);
  const ShownModel after = model_of(project);
  ASSERT_EQ(after.points.size(), before.points.size());
  std::size_t changed = 0, wall = 0;
  for (std::size_t k = 0; k < after.points.size(); ++k) {
    const bool on_wall = after.points.node[k] == static_cast<std::uint32_t>(room.wall);
    wall += on_wall;
    if (on_wall) {
      changed += after.points.rgba[k] != before.points.rgba[k];
    } else {
      EXPECT_EQ(after.points.rgba[k], before.points.rgba[k]) << "point " << k;
    }
  }
  EXPECT_GT(wall, 1000u);
  EXPECT_EQ(changed, wall);
  EXPECT_NEAR(mean_lab(after, room.wall).x(), mean_lab(before, room.wall).x() - 10.0, 0.5);
  test::expect_identical(project.load_scan(room.scan), scan_before);  // the scan never changes

  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(model_of(project).points.rgba, before.points.rgba);
  ASSERT_TRUE(project.redo().has_value());
  EXPECT_EQ(model_of(project).points.rgba, after.points.rgba);
}

TEST(Recolor, AGroupsEditReachesChildrenThatDoNotOverrideIt) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const RoomObjects room = segment_room(project);
  const ShownModel before = model_of(project);
  RecolorSettings group;
  group.node = room.room;
  group.set.brightness = 10.0;
  recolor_object(project, group);
  RecolorSettings floor;
  floor.node = room.floor;
  floor.set.brightness = 0.0;  // the floor keeps its lightness
  recolor_object(project, floor);
  const ShownModel after = model_of(project);
  const auto wall = static_cast<std::uint32_t>(room.wall);
  const auto floor_id = static_cast<std::uint32_t>(room.floor);
  EXPECT_NEAR(mean_lab(after, wall).x(), mean_lab(before, wall).x() + 10.0, 0.5);
  EXPECT_NEAR(mean_lab(after, floor_id).x(), mean_lab(before, floor_id).x(), 0.5);
  // --reset: the floor inherits the group's brightness again.
  RecolorSettings reset;
  reset.node = room.floor;
  reset.reset = true;
  recolor_object(project, reset);
  EXPECT_NEAR(mean_lab(model_of(project), floor_id).x(), mean_lab(before, floor_id).x() + 10.0,
              0.5);
}

TEST(Recolor, EditsSurviveReopeningTheProject) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  Colours shown;
  store::ColorEdit expected;
  {
    store::Project project = store::Project::create(file);
    const RoomObjects room = segment_room(project);
    RecolorSettings settings;
    settings.node = room.wall;
    settings.set.saturation = 0.3;
    settings.set.gamma = 1.4;
    recolor_object(project, settings);
    expected.saturation = 0.3;
    expected.gamma = 1.4;
    shown = model_of(project).points.rgba;
  }
  store::Project project = store::Project::open(file);
  EXPECT_EQ(project.object_nodes().back().color, expected);
  EXPECT_EQ(model_of(project).points.rgba, shown);
  EXPECT_TRUE(project.check().damage.empty());
}

TEST(Recolor, BadRequestsAreRefusedAndChangeNothing) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const RoomObjects room = segment_room(project);
  const std::int64_t revision = project.revision();
  RecolorSettings missing;
  missing.node = 99;
  missing.set.brightness = 5.0;
  EXPECT_THROW(recolor_object(project, missing), core::InputError);
  RecolorSettings too_bright;
  too_bright.node = room.wall;
  too_bright.set.brightness = 250.0;
  EXPECT_THROW(recolor_object(project, too_bright), core::InputError);
  CloneSettings two_sources;
  two_sources.target = room.wall;
  two_sources.source_node = room.floor;
  two_sources.source_color = std::array<std::uint8_t, 3>{1, 2, 3};
  EXPECT_THROW(clone_color(project, two_sources), core::InputError);
  CloneSettings outside;
  outside.target = room.wall;
  outside.source_region = PixelRect{room.scan, 0, 5, 700, 800};
  EXPECT_THROW(clone_color(project, outside), core::InputError);
  CloneSettings into_itself;
  into_itself.target = room.room;
  into_itself.source_node = room.wall;
  EXPECT_THROW(clone_color(project, into_itself), core::InputError);
  EXPECT_EQ(project.revision(), revision);
}

// The colours of a CSV export, sorted.
std::vector<std::array<int, 3>> csv_colours(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_TRUE(line.ends_with(",r,g,b")) << line;
  std::vector<std::array<int, 3>> out;
  while (std::getline(in, line)) {
    std::array<int, 3> c{};
    std::size_t end = line.size();
    for (int k = 2; k >= 0; --k) {
      const std::size_t comma = line.rfind(',', end - 1);
      c[static_cast<std::size_t>(k)] = std::stoi(line.substr(comma + 1, end - comma - 1));
      end = comma;
    }
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// An export holds what the model shows: the edited colours, without the
// hidden objects' points; asked for, the recorded colours of every point.
TEST(Export, WritesWhatTheModelShowsUnlessAskedForTheRecording) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const RoomObjects room = segment_room(project);
  RecolorSettings warm;
  warm.node = room.wall;
  warm.set.hue_deg = 90.0;
  warm.set.brightness = 15.0;
  recolor_object(project, warm);
  edit_node(project, {room.floor, std::nullopt, true, std::nullopt, {}});  // hide the floor
  SelectionTools tools;
  const std::size_t deleted = tools.select(project, select_at(room.scan, 90, 0)).selected_pixels;
  const NodeCommandResult far = tools.commit(project, {room.scan, "far wall", std::nullopt});
  delete_node(project, {far.node_id, DeletedPoints::kDeleted, {}});
  const ShownModel model = model_of(project);  // without the deleted points
  std::vector<std::array<int, 3>> shown;
  std::size_t floor = 0;
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    const auto& c = model.points.rgba[k];
    if (model.points.node[k] == static_cast<std::uint32_t>(room.floor)) {
      ++floor;
    } else {
      shown.push_back({c[0], c[1], c[2]});
    }
  }
  std::sort(shown.begin(), shown.end());
  ASSERT_GT(floor, 1000u);

  ExportSettings settings;
  settings.format = ExportFormat::kCsv;
  settings.output = dir / "shown.csv";
  const ExportResult result = export_project(project, settings);
  EXPECT_EQ(result.hidden, floor);
  EXPECT_EQ(result.deleted, deleted);
  EXPECT_EQ(result.points, shown.size());
  EXPECT_EQ(csv_colours(settings.output), shown);

  settings.colors = ExportColors::kRecorded;
  settings.all_points = true;
  settings.output = dir / "recorded.csv";
  const ExportResult all = export_project(project, settings);
  EXPECT_EQ(all.hidden + all.deleted, 0u);
  EXPECT_EQ(all.points, model.points.size() + deleted);
  const acquisition::Scan scan = project.load_scan(room.scan);
  const acquisition::ScanGeometry geometry = *store::load_geometry(project, room.scan);
  std::vector<std::array<int, 3>> recorded;
  for (std::size_t i = 0; i < scan.pixel_count(); ++i) {
    if (acquisition::in_model(scan, geometry, i))
      recorded.push_back({scan.rgb[3 * i], scan.rgb[3 * i + 1], scan.rgb[3 * i + 2]});
  }
  std::sort(recorded.begin(), recorded.end());
  EXPECT_EQ(csv_colours(settings.output), recorded);

  // A grid format keeps the grid: the hidden floor's pixels have no return.
  ExportSettings ptx;
  ptx.format = ExportFormat::kPtx;
  ptx.output = dir / "room.ptx";
  EXPECT_EQ(export_project(project, ptx).hidden, floor);
  const std::vector<acquisition::Scan> back = acquisition::read_ptx(ptx.output);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(acquisition::count_valid(back.front()),
            acquisition::count_valid(scan) - floor - deleted);
}

TEST(Clone, TheTargetTakesTheSourcesColoursAsShown) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  const RoomObjects room = segment_room(project);
  RecolorSettings warm;
  warm.node = room.floor;
  warm.set.hue_deg = 40.0;
  warm.set.saturation = 3.0;
  recolor_object(project, warm);
  CloneSettings clone;
  clone.target = room.wall;
  clone.source_node = room.floor;
  const CloneResult out = clone_color(project, clone);
  EXPECT_GT(out.source_points, 1000u);
  EXPECT_GT(out.target_points, 1000u);
  const ShownModel model = model_of(project);
  const Eigen::Vector3d floor = mean_lab(model, static_cast<std::uint32_t>(room.floor));
  const Eigen::Vector3d wall = mean_lab(model, static_cast<std::uint32_t>(room.wall));
  EXPECT_LT(acquisition::delta_e(floor, wall), 1.0)
      << floor.transpose() << " / " << wall.transpose();
  // Painting one colour (its lightness detail kept: what leaves the sRGB
  // gamut is clipped, so the mean lands within a little of the paint).
  CloneSettings paint;
  paint.target = room.wall;
  paint.source_color = std::array<std::uint8_t, 3>{30, 120, 60};
  clone_color(project, paint);
  const Eigen::Vector3d green = acquisition::srgb_to_lab({30, 120, 60});
  EXPECT_LT(acquisition::delta_e(mean_lab(model_of(project), static_cast<std::uint32_t>(room.wall)),
                                 green),
            2.0);
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_EQ(model_of(project).points.rgba, model.points.rgba);
}

// Mean and standard deviation of the shown L* of a node's points.
std::pair<double, double> lightness(const ShownModel& model, std::uint32_t node) {
  double sum = 0.0, squares = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    if (model.points.node[k] != node) continue;
    const auto& c = model.points.rgba[k];
    const double l = acquisition::srgb_to_lab({c[0], c[1], c[2]}).x();
    sum += l;
    squares += l * l;
    ++n;
  }
  const double mean = sum / static_cast<double>(n);
  return {mean, std::sqrt(std::max(0.0, squares / static_cast<double>(n) - mean * mean))};
}

// A textured room: every other column 40 levels darker, so each object
// has a spread of lightness. A clone maps the target's mean and spread
// onto the source's: an inverted ratio or a wrong offset shows.
TEST(Clone, TheTargetTakesTheSourcesMeanAndSpread) {
  SelectionTools tools;  // the selections: session state
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "p.sbproj");
  test::RoomScan room = test::shared_room();
  for (std::size_t i = 0; i < room.scan.pixel_count(); ++i) {
    if ((i % static_cast<std::size_t>(room.scan.columns)) % 2 != 0) continue;
    for (std::size_t c = 0; c < 3; ++c)
      room.scan.rgb[3 * i + c] =
          static_cast<std::uint8_t>(std::max(0, room.scan.rgb[3 * i + c] - 40));
  }
  const std::int64_t scan = test::insert_committed(project, room.scan);
  store::Project::Edit edit = project.begin_command("geometry", "{}");
  for (const store::EncodedLayer& layer : store::encode_geometry(room.geometry))
    project.put_layer(edit, scan, layer);
  edit.commit("{}");
  tools.select(project, select_at(scan, 0, -45));
  const std::int64_t floor = tools.commit(project, {scan, "floor", std::nullopt}).node_id;
  tools.select(project, select_at(scan, -20, 0));
  const std::int64_t wall = tools.commit(project, {scan, "wall", std::nullopt}).node_id;
  const auto source = lightness(model_of(project), static_cast<std::uint32_t>(wall));
  const auto before = lightness(model_of(project), static_cast<std::uint32_t>(floor));
  ASSERT_GT(std::abs(source.second - before.second), 1.0);  // the spreads differ
  CloneSettings clone;
  clone.target = floor;
  clone.source_node = wall;
  const CloneResult out = clone_color(project, clone);
  EXPECT_NEAR(out.transfer.scale.x(), source.second / before.second, 1e-6);
  const auto after = lightness(model_of(project), static_cast<std::uint32_t>(floor));
  EXPECT_NEAR(after.first, source.first, 0.5);
  EXPECT_NEAR(after.second, source.second, 0.5);
}

// The room scanned twice from the same place, the second copy's colours
// through gains in linear RGB: harmonising must find their inverse.
TEST(Harmonize, RecoversGainsAppliedToACopyOfAScanAndUndoRemovesThem) {
  const ScratchDir dir;
  const auto file = dir / "p.sbproj";
  const Eigen::Vector3d gains(1.25, 0.9, 1.1);
  Colours first_scan;
  {
    store::Project project = store::Project::create(file);
    store_room(project);
    first_scan = model_of(project).points.rgba;
    test::RoomScan copy = test::shared_room();
    for (std::size_t i = 0; i < copy.scan.pixel_count(); ++i) {
      for (std::size_t c = 0; c < 3; ++c) {
        copy.scan.rgb[3 * i + c] = acquisition::linear_to_srgb(
            gains[static_cast<int>(c)] * acquisition::srgb_to_linear(copy.scan.rgb[3 * i + c]));
      }
    }
    const std::int64_t second = test::insert_committed(project, copy.scan);
    store::Project::Edit edit = project.begin_command("geometry", "{}");
    for (const store::EncodedLayer& layer : store::encode_geometry(copy.geometry))
      project.put_layer(edit, second, layer);
    edit.commit("{}");

    core::Progress quiet;
    const HarmonizeCommandResult out = harmonize_project(project, {}, quiet);
    ASSERT_EQ(out.scans.size(), 2u);
    EXPECT_EQ(out.scans[1].reference, out.scans[0].id);
    EXPECT_EQ(out.scans[0].reference, out.scans[0].id);
    EXPECT_GT(out.pairs, 1000u);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(out.scans[1].correction.matrix(c, c) * gains[c], 1.0, 0.01) << "channel " << c;
      EXPECT_NEAR(out.scans[1].correction.offset[c], 0.0, 0.002);
    }
    EXPECT_GT(out.delta_e_before, 3.0);
    EXPECT_LT(out.delta_e_after, 0.5);
  }
  store::Project project = store::Project::open(file);
  const std::map<std::int64_t, store::ScanColorCorrection> stored =
      project.scan_color_corrections();
  ASSERT_EQ(stored.size(), 2u);
  EXPECT_TRUE(stored.begin()->second.identity());
  // The copy now shows the first scan's colours.
  const ShownModel model = model_of(project);
  ASSERT_EQ(model.points.size(), 2 * first_scan.size());
  std::size_t off = 0;
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    const auto& c = model.points.rgba[k];
    const Eigen::Vector3d lab = acquisition::srgb_to_lab({c[0], c[1], c[2]});
    double nearest = 1e9;
    for (const auto& f :
         {std::array<std::uint8_t, 3>{120, 120, 120}, std::array<std::uint8_t, 3>{40, 60, 90},
          std::array<std::uint8_t, 3>{200, 30, 30}, std::array<std::uint8_t, 3>{200, 200, 190}})
      nearest = std::min(nearest, acquisition::delta_e(lab, acquisition::srgb_to_lab(f)));
    off += nearest > 1.5;
  }
  EXPECT_EQ(off, 0u);
  EXPECT_TRUE(project.check().damage.empty());
  ASSERT_TRUE(project.undo().has_value());
  EXPECT_TRUE(project.scan_color_corrections().empty());
}

}  // namespace
}  // namespace scanbench::modeling

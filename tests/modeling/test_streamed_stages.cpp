// The streamed stages: the cache of loaded scans, the pairs of scans that
// may share a surface, and a merge that holds only a few scans at once yet
// decides as the merge of every scan in memory does.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <numbers>
#include <vector>

#include "acquisition/formats/point_export.hpp"
#include "core/errors.hpp"
#include "modeling/export_command.hpp"
#include "modeling/geometry_command.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/scan_overlaps.hpp"
#include "modeling/store/typed_layers.hpp"
#include "registration/color_harmonization.hpp"
#include "registration/merge.hpp"
#include "room_project.hpp"
#include "support/test_support.hpp"

namespace scanbench::modeling {
namespace {

using test::ScratchDir;

store::StoredScanSummary summary_with_box(std::int64_t id, Eigen::Vector3d lo, Eigen::Vector3d hi) {
  store::StoredScanSummary stored;
  stored.id = id;
  stored.summary.bbox_world = Eigen::AlignedBox3d(lo, hi);
  return stored;
}

TEST(OverlappingPairs, PairsTheBoxesThatReachEachOtherWithinTheMargin) {
  const std::vector<store::StoredScanSummary> scans{
      summary_with_box(1, {0, 0, 0}, {10, 10, 3}),
      summary_with_box(2, {40, 0, 0}, {50, 10, 3}),     // 30 m from the first
      summary_with_box(3, {8, 8, 0}, {20, 20, 3}),      // overlaps the first
      summary_with_box(4, {23, 0, 0}, {30, 5, 3}),      // 3 m from the third
      summary_with_box(5, {0, 0, 100}, {10, 10, 103}),  // above everything
      store::StoredScanSummary{}};                      // no valid point
  const std::vector<ScanPair> pairs = overlapping_pairs(scans, 5.0);
  EXPECT_EQ(pairs, (std::vector<ScanPair>{{0, 2}, {2, 3}}));
  EXPECT_EQ(overlapping_pairs(scans, 11.0), (std::vector<ScanPair>{{0, 2}, {1, 3}, {2, 3}}));
}

// Four rooms a few centimetres and degrees apart (they share every surface) and one a
// kilometre away (it shares none), with their geometry.
class StreamedStagesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const test::RoomScan& room = test::shared_room();
    for (const double x : {0.0, 0.05, 0.1, 0.15, 1000.0}) {
      acquisition::Scan scan = room.scan;
      scan.name = "room at " + std::to_string(x);
      scan.T_world_scan =
          Eigen::Translation3d(x, 0.02 * x, 0.0) * Eigen::AngleAxisd(x, Eigen::Vector3d::UnitZ());
      ids_.push_back(test::insert_committed(project_, scan));
    }
    store::Project::Edit edit = project_.begin_command("geometry", "{}");
    for (const std::int64_t id : ids_) {
      for (const store::EncodedLayer& layer : store::encode_geometry(room.geometry))
        project_.put_layer(edit, id, layer);
    }
    edit.commit("{}");
  }

  // Every scan of the project in memory, prepared.
  struct InMemory {
    std::vector<acquisition::Scan> scans;
    std::vector<acquisition::ScanGeometry> geometry;
    std::vector<Eigen::Isometry3d> poses;
    std::vector<registration::PreparedScan> prepared;
  };
  std::unique_ptr<InMemory> in_memory() const {
    auto all = std::make_unique<InMemory>();
    for (const std::int64_t id : ids_) {
      all->scans.push_back(project_.load_scan(id));
      all->geometry.push_back(*store::load_geometry(project_, id));
      all->poses.push_back(all->scans.back().T_world_scan);
    }
    for (std::size_t k = 0; k < ids_.size(); ++k)
      all->prepared.push_back(registration::prepare_scan(all->scans[k], all->geometry[k], 1));
    return all;
  }

  // The keep masks of the merge of every scan in memory.
  std::vector<std::vector<std::uint8_t>> merged_in_memory() const {
    const std::unique_ptr<InMemory> all = in_memory();
    registration::MergeResult result =
        registration::merge_by_sampling_rate(all->prepared, all->poses, {});
    std::vector<std::vector<std::uint8_t>> keep;
    for (registration::MergeScanResult& scan : result.scans) keep.push_back(std::move(scan.keep));
    return keep;
  }

  std::vector<std::uint8_t> stored_keep(std::int64_t id) const {
    return project_.load_layer<std::uint8_t>(id, store::layer::kKeep, store::ElementType::kU8)
        .value_or(std::vector<std::uint8_t>{});
  }

  // The memory one loaded room takes [bytes].
  std::uint64_t room_bytes() const {
    core::Progress progress;
    ScanCache cache(project_, std::uint64_t{1} << 40, 1, "test", progress);
    cache.plan({ids_[0]});
    return cache.get(ids_[0])->bytes;
  }

  ScratchDir dir_;
  store::Project project_ = store::Project::create(dir_ / "rooms.sbproj");
  std::vector<std::int64_t> ids_;
};

TEST_F(StreamedStagesTest, TheCacheKeepsWhatThePlanNeedsAndDropsTheRest) {
  core::Progress progress;
  const std::vector<std::int64_t> plan{ids_[0], ids_[1], ids_[0], ids_[2], ids_[0], ids_[1]};
  ScanCache cache(project_, std::uint64_t{1} << 40, 1, "test", progress);
  cache.plan(plan);
  for (const std::int64_t id : plan) EXPECT_EQ(cache.get(id)->id, id);
  EXPECT_EQ(cache.loads(), 3u);  // everything fits: each scan once
  // Room for two: the third scan pushes out the one needed last (scan 1,
  // not scan 0), which is loaded again at its turn.
  ScanCache tight(project_, room_bytes() * 5 / 2, 1, "test", progress);
  tight.plan(plan);
  for (const std::int64_t id : plan) EXPECT_EQ(tight.get(id)->id, id);
  EXPECT_EQ(tight.loads(), 4u);
  EXPECT_LE(tight.peak_bytes(), room_bytes() * 5 / 2);
}

// The per-pixel arrays two loads of a scan must agree on.
void expect_same_arrays(const LoadedScan& a, const LoadedScan& b) {
  EXPECT_EQ(a.scan.range_m, b.scan.range_m);
  EXPECT_EQ(a.scan.valid, b.scan.valid);
  EXPECT_EQ(a.scan.rgb, b.scan.rgb);
  EXPECT_EQ(a.scan.intensity, b.scan.intensity);
  EXPECT_EQ(a.scan.T_world_scan.matrix(), b.scan.T_world_scan.matrix());
  EXPECT_EQ(a.geometry.footprint_m, b.geometry.footprint_m);
  EXPECT_EQ(a.geometry.normal, b.geometry.normal);
  EXPECT_EQ(a.geometry.confidence, b.geometry.confidence);
  EXPECT_EQ(a.geometry.flags, b.geometry.flags);
  EXPECT_EQ(a.prepared.points, b.prepared.points);
  EXPECT_EQ(a.prepared.in_model, b.prepared.in_model);
  EXPECT_EQ(a.prepared.usable, b.prepared.usable);
  EXPECT_EQ(a.prepared.sample_area_m2, b.prepared.sample_area_m2);
  EXPECT_EQ(a.prepared.grid.has_value(), b.prepared.grid.has_value());
}

TEST_F(StreamedStagesTest, AScanLetGoBeforeThePlanIsDoneComesBackFromTheSpillAsItWasLoaded) {
  core::Progress progress;
  const std::vector<std::int64_t> plan{ids_[0], ids_[1], ids_[0], ids_[2], ids_[0], ids_[1]};
  std::map<std::int64_t, std::shared_ptr<const LoadedScan>> whole;
  ScanCache reference(project_, std::uint64_t{1} << 40, 1, "test", progress);
  reference.plan({ids_[0], ids_[1], ids_[2]});
  for (const std::int64_t id : {ids_[0], ids_[1], ids_[2]}) whole[id] = reference.get(id);

  // Nothing kept beyond the scan in hand: every return is a read.
  ScanCache spilled(project_, std::uint64_t{1} << 40, 1, "test", progress,
                    {.form = ScanForm::kWhole, .spill = true, .max_kept = 0});
  spilled.plan(plan);
  for (const std::int64_t id : plan) expect_same_arrays(*spilled.get(id), *whole.at(id));
  EXPECT_EQ(spilled.loads(), 3u);
  EXPECT_EQ(spilled.spill_reads(), 3u);
  EXPECT_LE(spilled.peak_bytes(), whole.at(ids_[0])->bytes + 1);

  // The merge's form: what the merge reads, the same; the rest dropped.
  ScanCache merge(project_, std::uint64_t{1} << 40, 1, "test", progress,
                  {.form = ScanForm::kMerge, .spill = true, .max_kept = 0});
  merge.plan(plan);
  for (const std::int64_t id : plan) {
    const std::shared_ptr<const LoadedScan> got = merge.get(id);
    const LoadedScan& expected = *whole.at(id);
    ASSERT_TRUE(got->prepared.grid.has_value());
    EXPECT_TRUE(got->prepared.points.empty());
    EXPECT_TRUE(got->scan.rgb.empty() && got->scan.valid.empty() && got->geometry.flags.empty());
    EXPECT_EQ(got->scan.range_m, expected.scan.range_m);
    EXPECT_EQ(got->geometry.normal, expected.geometry.normal);
    EXPECT_EQ(got->geometry.footprint_m, expected.geometry.footprint_m);
    EXPECT_EQ(got->prepared.sample_area_m2, expected.prepared.sample_area_m2);
    EXPECT_EQ(got->prepared.in_model, expected.prepared.in_model);
    EXPECT_EQ(got->prepared.usable, expected.prepared.usable);
    EXPECT_LT(got->bytes, expected.bytes * 6 / 10);
  }
  EXPECT_EQ(merge.spill_reads(), 3u);
}

// A grid of per-pixel directions comes back with its directions and its
// points, and a point index built again.
TEST(ScanCacheSpill, AScanWithPerPixelDirectionsComesBackWhole) {
  const test::RoomScan& room = test::shared_room();
  acquisition::Scan scan = room.scan;
  std::vector<Eigen::Vector3f> directions(scan.pixel_count());
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col)
      directions[scan.index(row, col)] = acquisition::direction(room.scan, row, col);
  }
  scan.angles = acquisition::PerPixelDirections{std::move(directions), false};
  ScratchDir dir;
  store::Project project = store::Project::create(dir / "grids.sbproj");
  std::vector<std::int64_t> ids;
  for (int k = 0; k < 2; ++k) ids.push_back(test::insert_committed(project, scan));
  store::Project::Edit edit = project.begin_command("geometry", "{}");
  for (const std::int64_t id : ids) {
    for (const store::EncodedLayer& layer : store::encode_geometry(room.geometry))
      project.put_layer(edit, id, layer);
  }
  edit.commit("{}");

  core::Progress progress;
  ScanCache reference(project, std::uint64_t{1} << 40, 1, "test", progress);
  reference.plan({ids[0]});
  const std::shared_ptr<const LoadedScan> whole = reference.get(ids[0]);
  ScanCache spilled(project, std::uint64_t{1} << 40, 1, "test", progress,
                    {.form = ScanForm::kMerge, .spill = true, .max_kept = 0});
  spilled.plan({ids[0], ids[1], ids[0]});
  spilled.get(ids[0]);
  spilled.get(ids[1]);
  const std::shared_ptr<const LoadedScan> back = spilled.get(ids[0]);
  EXPECT_EQ(spilled.spill_reads(), 1u);
  EXPECT_EQ(std::get<acquisition::PerPixelDirections>(back->scan.angles),
            std::get<acquisition::PerPixelDirections>(whole->scan.angles));
  EXPECT_EQ(back->prepared.points, whole->prepared.points);  // kept: no grid to recompute them
  EXPECT_EQ(back->prepared.sample_area_m2, whole->prepared.sample_area_m2);
  ASSERT_NE(back->prepared.tree, nullptr);
  std::size_t compared = 0;
  for (std::size_t i = 0; i < scan.pixel_count(); i += 97) {
    if (!whole->prepared.usable[i]) continue;
    const Eigen::Vector3f near = whole->prepared.points[i] + Eigen::Vector3f(0.003f, 0, 0);
    ASSERT_EQ(registration::associate(back->prepared, near),
              registration::associate(whole->prepared, near));
    ++compared;
  }
  EXPECT_GT(compared, 100u);
}

// The points a merge recomputes where its form dropped them are those
// prepare_scan computed, bit for bit.
TEST(SphericalDirections, GiveTheDirectionsOfEveryPixelBitForBit) {
  const acquisition::Scan& scan = test::shared_room().scan;
  ASSERT_TRUE(scan.is_spherical());
  const acquisition::SphericalDirections directions(scan);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col)
      ASSERT_EQ(directions(row, col), acquisition::direction(scan, row, col)) << row << " " << col;
  }
}

TEST_F(StreamedStagesTest, DecidesAsTheMergeOfEveryScanInMemoryWhateverItsLimit) {
  const std::vector<std::vector<std::uint8_t>> expected = merged_in_memory();
  std::size_t redundant = 0;
  for (const auto& keep : expected) redundant += std::count(keep.begin(), keep.end(), 0);
  ASSERT_GT(redundant, 0u);  // the rooms do share surfaces
  for (const std::uint64_t limit : {room_bytes() * 5 / 2, std::uint64_t{1} << 40}) {
    core::Progress progress;
    const MergeCommandResult out = merge_project(project_, {}, progress, limit);
    ASSERT_EQ(out.scans.size(), ids_.size());
    for (std::size_t k = 0; k < ids_.size(); ++k) {
      const std::vector<std::uint8_t> keep = stored_keep(ids_[k]);
      ASSERT_EQ(keep.size(), expected[k].size());
      EXPECT_TRUE(keep == expected[k]) << "scan " << k << " at limit " << limit;
      EXPECT_EQ(out.scans[k].counts.kept,
                static_cast<std::size_t>(std::count(keep.begin(), keep.end(), 1)));
    }
    // The far room keeps everything: no scan reaches it.
    EXPECT_EQ(out.scans.back().counts.redundant, 0u);
  }
}

TEST_F(StreamedStagesTest, RegistrationWithTwoScansInHandEqualsTheOneInMemory) {
  RegisterCommandSettings settings;
  settings.registration.coarse = registration::CoarseMethod::kNone;
  settings.registration.icp.threads = 1;
  const std::unique_ptr<InMemory> all = in_memory();
  const registration::RegistrationResult expected =
      registration::register_scans(all->prepared, all->poses, settings.registration);
  core::Progress progress;
  const RegisterCommandResult out =
      register_project(project_, settings, progress, room_bytes() * 5 / 2);
  ASSERT_EQ(out.result.T_world_scan.size(), ids_.size());
  for (std::size_t k = 0; k < ids_.size(); ++k) {
    EXPECT_TRUE(out.result.T_world_scan[k].isApprox(expected.T_world_scan[k], 1e-12)) << k;
    EXPECT_TRUE(project_.scans()[k].summary.T_world_scan.isApprox(expected.T_world_scan[k], 1e-12));
  }
  EXPECT_EQ(out.result.edges.size(), expected.edges.size());
  EXPECT_EQ(out.result.rms_m, expected.rms_m);
  // The chain's 4 pairs, and the 6 pairs among the rooms that share
  // surfaces: the far room's bounds meet none (all pairs: 4 + 10).
  EXPECT_EQ(out.result.pair_tests, 10u);
  // The stored bounds are the scans' at their new poses.
  const acquisition::Scan moved = project_.load_scan(ids_[1]);
  EXPECT_TRUE(project_.scans()[1].summary.bbox_world->isApprox(*acquisition::world_bounds(moved)));
}

// The global refinement tests at most max_overlap_tests_per_scan earlier
// scans per scan: with 2, the fourth room is tested against two of the
// three rooms before it.
TEST_F(StreamedStagesTest, RegistrationTestsAtMostTheSetNumberOfEarlierScansPerScan) {
  RegisterCommandSettings settings;
  settings.registration.coarse = registration::CoarseMethod::kNone;
  settings.registration.max_overlap_tests_per_scan = 2;
  core::Progress progress;
  const RegisterCommandResult out = register_project(project_, settings, progress, std::nullopt);
  EXPECT_EQ(out.result.pair_tests, 4u + 1u + 2u + 2u);  // the chain, then 1 + 2 + 2
  std::map<int, int> tested;
  for (const registration::EdgeReport& edge : out.result.edges) ++tested[edge.source];
  EXPECT_EQ(out.result.edges.size(), 5u);
  for (const auto& [source, count] : tested) EXPECT_LE(count, 2) << "scan " << source;
  for (const Eigen::Isometry3d& pose : out.result.T_world_scan)
    EXPECT_TRUE(pose.matrix().allFinite());
}

TEST_F(StreamedStagesTest, HarmonizationWithOneScanInHandFindsThePairsOfTheOneInMemory) {
  const HarmonizeCommandSettings settings;
  const std::unique_ptr<InMemory> all = in_memory();
  // Each near room may overlap the three others: the command shares each
  // scan's pairs among them.
  registration::ColorPairSettings per_link = settings.pairs;
  per_link.max_pairs_per_overlap = registration::link_pair_budget(settings.pairs, 3, 3);
  ASSERT_EQ(per_link.max_pairs_per_overlap, settings.pairs.max_pairs_per_scan / 3);
  const std::vector<registration::ColorPair> expected =
      registration::find_color_pairs(all->prepared, all->poses, per_link);
  ASSERT_GT(expected.size(), 1000u);
  core::Progress progress;
  const HarmonizeCommandResult out =
      harmonize_project(project_, settings, progress, room_bytes() * 3 / 2);
  EXPECT_EQ(out.pairs, expected.size());
  // The same pairs in the same order: the same sum, to the last bit.
  EXPECT_EQ(out.delta_e_before, mean_pair_delta_e(expected, {}));
  std::vector<std::size_t> pairs_of(ids_.size(), 0);
  for (const registration::ColorPair& pair : expected) {
    ++pairs_of[pair.scan_a];
    ++pairs_of[pair.scan_b];
  }
  const registration::HarmonizeResult solved =
      registration::harmonize_colors(expected, ids_.size(), settings.solve);
  for (std::size_t k = 0; k < ids_.size(); ++k) {
    EXPECT_TRUE(out.scans[k].correction.matrix.isApprox(solved.corrections[k].matrix)) << k;
    EXPECT_EQ(out.scans[k].pairs, pairs_of[k]) << k;
    EXPECT_EQ(out.scans[k].pairs == 0, k == ids_.size() - 1);  // the far room pairs with none
  }
}

// Cancels the stage at its second unit.
class CancelAtSecond : public core::Progress {
 public:
  void update(const core::ProgressStep& step) override {
    if (step.done == 2) request_cancel();
    ++updates;
  }
  int updates = 0;
};

TEST_F(StreamedStagesTest, ExportWritesScanByScanTheFileOfEveryScanInMemory) {
  core::Progress quiet;
  merge_project(project_, {}, quiet, std::uint64_t{1} << 40);
  const std::unique_ptr<InMemory> all = in_memory();
  std::vector<std::vector<std::uint8_t>> keep;
  std::vector<const std::vector<std::uint8_t>*> keep_of;
  std::vector<const acquisition::ScanGeometry*> geometry_of;
  for (std::size_t k = 0; k < ids_.size(); ++k) keep.push_back(stored_keep(ids_[k]));
  for (std::size_t k = 0; k < ids_.size(); ++k) {
    keep_of.push_back(&keep[k]);
    geometry_of.push_back(&all->geometry[k]);
  }
  acquisition::write_ply(dir_ / "in_memory.ply", all->scans, geometry_of, keep_of);
  ExportSettings settings;
  settings.format = ExportFormat::kPly;
  settings.merged = true;
  settings.output = dir_ / "streamed.ply";
  const ExportResult result = export_project(project_, settings);
  const std::string in_memory_ply = test::read_file_bytes(dir_ / "in_memory.ply");
  EXPECT_EQ(test::read_file_bytes(dir_ / "streamed.ply"), in_memory_ply);
  EXPECT_NE(in_memory_ply.find("element vertex " + std::to_string(result.points) + "\n"),
            std::string::npos)
      << "the points reported are the points written";
  // A band of rows at a time (one row, seven): the same file, for a scan
  // too large to hold.
  for (const std::size_t band_pixels : {std::size_t{1}, std::size_t{7 * 720}}) {
    settings.band_pixels = band_pixels;
    settings.output = dir_ / ("bands" + std::to_string(band_pixels) + ".ply");
    EXPECT_EQ(export_project(project_, settings).points, result.points);
    EXPECT_EQ(test::read_file_bytes(settings.output), in_memory_ply) << band_pixels;
  }
  settings.band_pixels = ExportSettings{}.band_pixels;

  // Cancelled after the second scan: no file, not even a partial one.
  settings.output = dir_ / "cancelled.las";
  settings.format = ExportFormat::kLas;
  CancelAtSecond cancel;
  EXPECT_THROW(export_project(project_, settings, &cancel), core::Cancelled);
  EXPECT_EQ(cancel.updates, 2);
  for (const auto& entry : std::filesystem::directory_iterator(dir_.path())) {
    EXPECT_EQ(entry.path().filename().string().find("cancelled"), std::string::npos)
        << entry.path();
  }
}

// The room cast over 600 rows of 0.1° (three tiles of the window fits)
// and 300 columns of 0.3°.
acquisition::Scan tall_room() {
  constexpr double kDeg = std::numbers::pi / 180.0;
  acquisition::Scan scan = acquisition::make_empty_scan(600, 300, false, false);
  scan.angles = acquisition::SphericalAngles{-60.0 * kDeg, 0.3 * kDeg, 25.0 * kDeg, -0.1 * kDeg};
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col) {
      const auto [range, object] =
          test::room_detail::cast(acquisition::direction_precise(scan, row, col));
      if (object == test::kNothing) continue;
      const std::size_t i = scan.index(row, col);
      scan.valid[i] = 1;
      scan.range_m[i] = static_cast<float>(range * (1.0 + 1e-4 * ((i * 7919) % 13)));
    }
  }
  return scan;
}

TEST(GeometryStage, ComputesAGridBandByBandAsTheWholeScanInMemory) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "tall.sbproj");
  const acquisition::Scan scan = tall_room();
  const std::int64_t id = test::insert_committed(project, scan);
  acquisition::GeometrySettings settings;
  settings.estimate_range_noise = true;
  const acquisition::GeometryResult whole = acquisition::compute_geometry(scan, settings);
  ASSERT_GT(whole.normals, scan.pixel_count() / 4);
  core::Progress quiet;
  // One band (the default), then a band per tile (three).
  for (const std::size_t band_pixels : {kGeometryBandPixels, std::size_t{1}}) {
    SCOPED_TRACE(band_pixels);
    const GeometryCommandResult result = geometry_project(project, settings, quiet, band_pixels);
    ASSERT_EQ(result.scans.size(), 1u);
    EXPECT_EQ(result.scans[0].normals, whole.normals);
    EXPECT_EQ(result.scans[0].mixed_pixels, whole.mixed_pixels);
    EXPECT_EQ(result.scans[0].edge_pixels, whole.edge_pixels);
    EXPECT_TRUE(test::same_bytes(result.scans[0].range_noise, whole.noise.noise));
    const std::optional<acquisition::ScanGeometry> stored = store::load_geometry(project, id);
    ASSERT_TRUE(stored.has_value());
    EXPECT_TRUE(test::same_bytes(stored->normal, whole.geometry.normal));
    EXPECT_TRUE(test::same_bytes(stored->footprint_m, whole.geometry.footprint_m));
    EXPECT_TRUE(test::same_bytes(stored->confidence, whole.geometry.confidence));
    EXPECT_EQ(stored->flags, whole.geometry.flags);
  }
  EXPECT_TRUE(project.check().damage.empty());
}

TEST(GeometryStage, ComputesAGridOfPerPixelDirectionsBandByBandAsInMemory) {
  const ScratchDir dir;
  store::Project project = store::Project::create(dir / "tall.sbproj");
  acquisition::Scan scan = tall_room();
  std::vector<Eigen::Vector3f> directions(scan.pixel_count());
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.columns; ++col)
      directions[scan.index(row, col)] = acquisition::direction(scan, row, col);
  }
  scan.angles = acquisition::PerPixelDirections{std::move(directions), false};
  const std::int64_t id = test::insert_committed(project, scan);
  const acquisition::GeometryResult whole = acquisition::compute_geometry(scan, {});
  core::Progress quiet;
  geometry_project(project, {}, quiet, 1);  // a band per tile of the window fits
  const std::optional<acquisition::ScanGeometry> stored = store::load_geometry(project, id);
  ASSERT_TRUE(stored.has_value());
  EXPECT_TRUE(test::same_bytes(stored->normal, whole.geometry.normal));
  EXPECT_TRUE(test::same_bytes(stored->footprint_m, whole.geometry.footprint_m));
  EXPECT_EQ(stored->flags, whole.geometry.flags);
}

TEST_F(StreamedStagesTest, ALimitTooSmallToLoadAScanIsRefusedAndChangesNothing) {
  const std::int64_t revision = project_.revision();
  core::Progress progress;
  try {
    // The merge's form of a room takes half of it, but loading one takes
    // it whole.
    merge_project(project_, {}, progress, room_bytes() * 3 / 4);
    FAIL() << "a room being loaded does not fit";
  } catch (const core::MemoryShortage& e) {
    EXPECT_NE(std::string(e.what()).find("--memory-limit"), std::string::npos) << e.what();
  }
  EXPECT_EQ(project_.revision(), revision);
  for (const std::int64_t id : ids_) EXPECT_TRUE(stored_keep(id).empty());
}

}  // namespace
}  // namespace scanbench::modeling

#include "modeling/carried_objects.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <utility>

#include "core/errors.hpp"
#include "modeling/command_json.hpp"
#include "modeling/node_tree.hpp"
#include "modeling/object_carry.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/store/typed_layers.hpp"
#include "registration/prepared_scan.hpp"
#include "segmentation/segmentation_grid.hpp"

namespace scanbench::modeling {

namespace {

// How each object's commit carried it (the channel it grew with, the
// scanner's noise), by node id, from the journal's done commits that
// carried their object. Objects no such commit made (a commit asked to
// stay in its scan, a proposal, a separated part) are not carried.
std::map<std::int64_t, CommitSettings> commit_settings_by_node(const store::Project& project) {
  std::map<std::int64_t, CommitSettings> out;
  for (const store::CommandRecord& c : project.history()) {
    if (c.name != "commit" || c.state != store::CommandState::kDone) continue;
    const nlohmann::json result = nlohmann::json::parse(c.result, nullptr, false);
    if (!result.is_object() || !result.contains("node")) continue;
    CommitSettings settings = settings_from_json<CommitSettings>(
        c.settings, "command " + std::to_string(c.id), SettingsSource::kJournal);
    if (settings.other_scans) out[result["node"].get<std::int64_t>()] = std::move(settings);
  }
  return out;
}

// One scan decoded and prepared for carrying, at its pose to be.
struct Side {
  acquisition::Scan scan;
  acquisition::ScanGeometry geometry;
  registration::PreparedScan prepared;
  std::vector<std::uint32_t> membership;
  std::vector<std::uint8_t> carried;
};

Side load_side(const store::Project& project, std::int64_t id,
               const std::map<std::int64_t, Eigen::Isometry3d>& poses) {
  Side side;
  side.scan = project.load_scan(id);
  if (const auto pose = poses.find(id); pose != poses.end()) side.scan.T_world_scan = pose->second;
  std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project, id);
  if (!geometry) {
    core::FilePosition position;
    position.detail = "scan " + std::to_string(id);
    throw core::InputError(project.path().string(), position,
                           "has a normal layer but not the rest of its geometry (damaged?)");
  }
  side.geometry = std::move(*geometry);
  side.prepared = registration::prepare_scan(side.scan, side.geometry, 0);
  side.membership = load_membership(project, id, side.scan.pixel_count());
  side.carried = load_carried(project, id, side.scan.pixel_count());
  return side;
}

bool drawn(const Side& side, std::size_t p) {
  const std::uint32_t owner = side.membership[p];
  return owner != 0 && owner != store::kDeletedPoints && side.carried[p] == 0;
}

// The grid a target grows on, one per noise model the commits used.
class Grids {
 public:
  explicit Grids(const Side& target) : target_(target) {}
  const segmentation::SegmentationGrid& with(const acquisition::RangeNoise& noise) {
    for (const auto& [n, grid] : grids_) {
      if (n.noise_m == noise.noise_m && n.noise_per_m == noise.noise_per_m) return grid;
    }
    segmentation::GridSettings settings;
    settings.range_noise = noise;
    grids_.emplace_back(noise,
                        segmentation::prepare_grid(target_.scan, target_.geometry, settings));
    return grids_.back().second;
  }

 private:
  const Side& target_;
  std::vector<std::pair<acquisition::RangeNoise, segmentation::SegmentationGrid>> grids_;
};

}  // namespace

std::vector<std::uint8_t> load_carried(const store::Project& project, std::int64_t scan_id,
                                       std::size_t pixels) {
  auto stored =
      project.load_layer<std::uint8_t>(scan_id, store::layer::kCarried, store::ElementType::kU8);
  return stored ? std::move(*stored) : std::vector<std::uint8_t>(pixels, 0);
}

CarriedAgain carry_objects_again(const store::Project& project,
                                 const std::map<std::int64_t, Eigen::Isometry3d>& poses,
                                 core::Progress& progress) {
  CarriedAgain out;
  std::vector<std::int64_t> scans;  // with geometry
  bool segmented = false;
  for (const store::StoredScanSummary& stored : project.scans()) {
    const std::vector<std::string> layers = project.layer_names(stored.id);
    const auto has = [&](const char* name) {
      return std::find(layers.begin(), layers.end(), name) != layers.end();
    };
    if (!has(store::layer::kNormal)) continue;
    scans.push_back(stored.id);
    segmented = segmented || has(store::layer::kMembership);
  }
  if (!segmented) return out;
  const std::map<std::int64_t, CommitSettings> commits = commit_settings_by_node(project);
  if (commits.empty()) return out;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const std::int64_t target_id = scans[k];
    progress.update({"register", k, scans.size(), "carrying the objects again"});
    progress.throw_if_cancelled("register");
    Side target = load_side(project, target_id, poses);
    const std::vector<std::uint32_t> before = target.membership;
    std::vector<std::uint8_t> open(target.membership.size());
    for (std::size_t p = 0; p < open.size(); ++p) {
      if (target.carried[p] != 0 && target.membership[p] != 0 &&
          target.membership[p] != store::kDeletedPoints) {
        target.membership[p] = 0;
        ++out.released;
      }
      target.carried[p] = 0;
      open[p] = target.membership[p] == 0;
    }
    Grids grids(target);
    for (const std::int64_t source_id : scans) {
      if (source_id == target_id) continue;
      const Side source = load_side(project, source_id, poses);
      std::set<std::uint32_t> objects;  // drawn there, and carried by their commit
      for (std::size_t p = 0; p < source.membership.size(); ++p) {
        if (drawn(source, p) && commits.count(source.membership[p]) != 0)
          objects.insert(source.membership[p]);
      }
      for (const std::uint32_t object : objects) {
        std::vector<std::uint32_t> labels(source.membership.size(), 0);
        for (std::size_t p = 0; p < labels.size(); ++p)
          labels[p] = drawn(source, p) && source.membership[p] == object ? 1 : 0;
        const CommitSettings& commit = commits.at(object);
        CarrySettings settings;
        settings.transfer.noise = commit.range_noise;
        settings.grow = commit.grow;
        const segmentation::SegmentationGrid* grid =
            settings.grow ? &grids.with(settings.transfer.noise) : nullptr;
        const segmentation::PixelSet joins =
            carry_object({&source.prepared, source.scan.T_world_scan, labels},
                         {&target.prepared, target.scan.T_world_scan, grid, open}, settings);
        for (const std::uint32_t q : joins) {
          target.membership[q] = object;
          target.carried[q] = 1;
          open[q] = 0;
        }
        out.carried_points += joins.size();
      }
    }
    if (target.membership != before) {
      out.memberships.emplace(target_id, std::move(target.membership));
      out.carried.emplace(target_id, std::move(target.carried));
    }
  }
  return out;
}

}  // namespace scanbench::modeling

#include "modeling/carried_objects.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
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

// Where each scan's objects were drawn (not carried there), for the objects
// their commit carried: the pixels, ascending, by object. Only these act as
// the sources of carrying.
using DrawnPixels = std::map<std::uint32_t, std::vector<std::uint32_t>>;

DrawnPixels drawn_pixels(const std::vector<std::uint32_t>& membership,
                         const std::vector<std::uint8_t>& carried,
                         const std::map<std::int64_t, CommitSettings>& commits) {
  DrawnPixels out;
  for (std::size_t p = 0; p < membership.size(); ++p) {
    const std::uint32_t owner = membership[p];
    if (owner == 0 || owner == store::kDeletedPoints || carried[p] != 0) continue;
    if (commits.count(owner) != 0) out[owner].push_back(static_cast<std::uint32_t>(p));
  }
  return out;
}

// The grid a target grows on, one per noise model the commits used (none:
// the target's own).
class Grids {
 public:
  Grids(const acquisition::Scan& scan, const acquisition::ScanGeometry& geometry)
      : scan_(scan), geometry_(geometry) {}
  const segmentation::SegmentationGrid& with(const std::optional<acquisition::RangeNoise>& given) {
    const acquisition::RangeNoise noise = given.value_or(geometry_.range_noise);
    for (const auto& [n, grid] : grids_) {
      if (n == noise) return grid;
    }
    segmentation::GridSettings settings;
    settings.range_noise = noise;
    grids_.emplace_back(noise, segmentation::prepare_grid(scan_, geometry_, settings));
    return grids_.back().second;
  }

 private:
  const acquisition::Scan& scan_;
  const acquisition::ScanGeometry& geometry_;
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
                                 std::span<const store::StoredScanSummary> scans,
                                 registration::ScanStream& stream,
                                 const std::vector<Eigen::Isometry3d>& poses,
                                 core::Progress& progress) {
  CarriedAgain out;
  const std::map<std::int64_t, CommitSettings> commits = commit_settings_by_node(project);
  if (commits.empty()) return out;
  const int n = static_cast<int>(scans.size());
  const auto pixels_of = [&scans](int k) {
    const acquisition::ScanSummary& s = scans[static_cast<std::size_t>(k)].summary;
    return static_cast<std::size_t>(s.rows) * static_cast<std::size_t>(s.columns);
  };
  // Each scan's layers are decoded once here, and the drawn pixels kept
  // (a small share of a scan); a target's layers once more below.
  std::vector<DrawnPixels> drawn(scans.size());
  std::vector<int> order;
  for (int k = 0; k < n; ++k) {
    const std::int64_t id = scans[static_cast<std::size_t>(k)].id;
    drawn[static_cast<std::size_t>(k)] =
        drawn_pixels(load_membership(project, id, pixels_of(k)),
                     load_carried(project, id, pixels_of(k)), commits);
  }
  // Each target, then the scans whose drawn objects it may take.
  for (int t = 0; t < n; ++t) {
    order.push_back(t);
    for (int from = 0; from < n; ++from) {
      if (from != t && !drawn[static_cast<std::size_t>(from)].empty()) order.push_back(from);
    }
  }
  stream.plan(order);
  for (int t = 0; t < n; ++t) {
    const std::int64_t target_id = scans[static_cast<std::size_t>(t)].id;
    progress.update(
        {"register", static_cast<std::size_t>(t), scans.size(), "carrying the objects again"});
    progress.throw_if_cancelled("register");
    const std::shared_ptr<const registration::PreparedScan> target = stream.get(t);
    const std::size_t pixels = pixels_of(t);
    std::vector<std::uint32_t> membership = load_membership(project, target_id, pixels);
    std::vector<std::uint8_t> carried = load_carried(project, target_id, pixels);
    const std::vector<std::uint32_t> before = membership;
    std::vector<std::uint8_t> open(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
      if (carried[p] != 0 && membership[p] != 0 && membership[p] != store::kDeletedPoints) {
        membership[p] = 0;
        ++out.released;
      }
      carried[p] = 0;
      open[p] = membership[p] == 0;
    }
    Grids grids(*target->scan, *target->geometry);
    for (int from = 0; from < n; ++from) {
      if (from == t || drawn[static_cast<std::size_t>(from)].empty()) continue;
      const std::shared_ptr<const registration::PreparedScan> source = stream.get(from);
      for (const auto& [object, drawn_at] : drawn[static_cast<std::size_t>(from)]) {
        std::vector<std::uint32_t> labels(pixels_of(from), 0);
        for (const std::uint32_t p : drawn_at) labels[p] = 1;
        const CommitSettings& commit = commits.at(object);
        CarrySettings settings;
        settings.transfer.noise = commit.range_noise;
        settings.grow = commit.grow;
        // A scattered target has no grid to grow on: it takes the carried points.
        const segmentation::SegmentationGrid* grid = settings.grow && !target->scan->is_scattered()
                                                         ? &grids.with(settings.transfer.noise)
                                                         : nullptr;
        const segmentation::PixelSet joins =
            carry_object({source.get(), poses[static_cast<std::size_t>(from)], labels},
                         {target.get(), poses[static_cast<std::size_t>(t)], grid, open}, settings);
        for (const std::uint32_t q : joins) {
          membership[q] = object;
          carried[q] = 1;
          open[q] = 0;
        }
        out.carried_points += joins.size();
      }
    }
    if (membership != before) {
      out.memberships.emplace(target_id, std::move(membership));
      out.carried.emplace(target_id, std::move(carried));
    }
  }
  return out;
}

}  // namespace scanbench::modeling

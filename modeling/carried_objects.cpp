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

// A target scan's object layers while objects are carried into it, and
// which of its points are still free to take one.
struct TargetLayers {
  std::vector<std::uint32_t> membership;
  std::vector<std::uint8_t> carried;
  std::vector<std::uint8_t> open;
};

// Gives the carried points of a target back to the pool (deleted points
// stay deleted); returns how many. Marks the free points open.
std::size_t release_carried(TargetLayers& layers) {
  std::size_t released = 0;
  layers.open.assign(layers.membership.size(), 0);
  for (std::size_t p = 0; p < layers.membership.size(); ++p) {
    std::uint32_t& owner = layers.membership[p];
    if (layers.carried[p] != 0 && owner != 0 && owner != store::kDeletedPoints) {
      owner = 0;
      ++released;
    }
    layers.carried[p] = 0;
    layers.open[p] = owner == 0;
  }
  return released;
}

// A prepared scan at a pose.
struct Posed {
  const registration::PreparedScan* scan = nullptr;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

// Carries each object drawn in `source` into `target` as its commit grew
// it, into the target's open points; returns how many points joined.
std::size_t carry_drawn(const Posed& source, const DrawnPixels& drawn,
                        const std::map<std::int64_t, CommitSettings>& commits, const Posed& target,
                        Grids& grids, TargetLayers& layers) {
  std::size_t joined = 0;
  for (const auto& [object, drawn_at] : drawn) {
    std::vector<std::uint32_t> labels(source.scan->in_model.size(), 0);
    for (const std::uint32_t p : drawn_at) labels[p] = 1;
    const CommitSettings& commit = commits.at(object);
    CarrySettings settings;
    settings.transfer.noise = commit.range_noise;
    settings.grow = commit.grow;
    // A scattered target has no grid to grow on: it takes the carried points.
    const segmentation::SegmentationGrid* grid = settings.grow && !target.scan->scan->is_scattered()
                                                     ? &grids.with(settings.transfer.noise)
                                                     : nullptr;
    const segmentation::PixelSet joins =
        carry_object({source.scan, source.pose, labels},
                     {target.scan, target.pose, grid, layers.open}, settings);
    for (const std::uint32_t q : joins) {
      layers.membership[q] = object;
      layers.carried[q] = 1;
      layers.open[q] = 0;
    }
    joined += joins.size();
  }
  return joined;
}

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
  const auto sources_of = [&drawn, n](int t) {
    std::vector<int> sources;
    for (int from = 0; from < n; ++from) {
      if (from != t && !drawn[static_cast<std::size_t>(from)].empty()) sources.push_back(from);
    }
    return sources;
  };
  for (int t = 0; t < n; ++t) {
    const std::vector<int> sources = sources_of(t);
    if (sources.empty()) continue;  // its carried points go back without it
    order.push_back(t);
    order.insert(order.end(), sources.begin(), sources.end());
  }
  stream.plan(order);
  for (int t = 0; t < n; ++t) {
    const std::int64_t target_id = scans[static_cast<std::size_t>(t)].id;
    progress.update(
        {"register", static_cast<std::size_t>(t), scans.size(), "carrying the objects again"});
    progress.throw_if_cancelled("register");
    const std::size_t pixels = pixels_of(t);
    TargetLayers layers{
        load_membership(project, target_id, pixels), load_carried(project, target_id, pixels), {}};
    const std::vector<std::uint32_t> before = layers.membership;
    out.released += release_carried(layers);
    const std::vector<int> sources = sources_of(t);
    if (!sources.empty()) {
      const std::shared_ptr<const registration::PreparedScan> target = stream.get(t);
      Grids grids(*target->scan, *target->geometry);
      for (const int from : sources) {
        const std::shared_ptr<const registration::PreparedScan> source = stream.get(from);
        out.carried_points +=
            carry_drawn({source.get(), poses[static_cast<std::size_t>(from)]},
                        drawn[static_cast<std::size_t>(from)], commits,
                        {target.get(), poses[static_cast<std::size_t>(t)]}, grids, layers);
      }
    }
    if (layers.membership != before) {
      out.memberships.emplace(target_id, std::move(layers.membership));
      out.carried.emplace(target_id, std::move(layers.carried));
    }
  }
  return out;
}

}  // namespace scanbench::modeling

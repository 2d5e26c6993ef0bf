#include "modeling/lod/update_lod.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/errors.hpp"
#include "core/parallel.hpp"
#include "modeling/lod/lod_schema.hpp"
#include "modeling/lod/lod_store.hpp"
#include "modeling/lod/octree_edit.hpp"
#include "modeling/lod/shown_points.hpp"
#include "modeling/scan_cache.hpp"

namespace scanbench::lod {
namespace {

using store::sqlite::Statement;

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What changed between the store's digest and a scan's pixels: as large as
// the digest bands the change touches, not as the scan.
struct ScanChanges {
  // For each digest band where a point the store holds is relabelled or
  // removed, every pixel's owner now (an object, or kNotShown for a point
  // that leaves the store). A held point changed where its object differs
  // from its pixel's owner here.
  std::map<int, std::vector<std::uint32_t>> now;
  std::vector<std::uint32_t> added_pixels;  // whose points the store must now hold
  std::vector<BuildPoint> added;            // those points, read
  // Where points were relabelled or removed (tile_of): ascending once
  // compare_owners returns.
  std::vector<std::uint64_t> tiles;
  std::uint64_t relabelled = 0, removed = 0;
  // The digest's bands that changed, as they are now (compress_owners).
  std::vector<std::pair<int, std::vector<std::uint8_t>>> bands;

  // The new owner of point `p`, which the store holds of this scan
  // (`scan`); none when it did not change.
  std::optional<std::uint32_t> changed_owner(const LodScan& scan, const LodPoint& p) const {
    const std::size_t band_pixels = static_cast<std::size_t>(scan.digest_rows) *
                                    static_cast<std::size_t>(std::max(scan.columns, 1));
    const auto band = now.find(static_cast<int>(p.pixel / band_pixels));
    if (band == now.end()) return std::nullopt;
    const std::uint32_t owner = band->second[p.pixel % band_pixels];
    if (owner == p.object) return std::nullopt;
    return owner;
  }
};

// Sorts `tiles` and drops repeats.
void sort_unique(std::vector<std::uint64_t>& tiles) {
  std::sort(tiles.begin(), tiles.end());
  tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
}

// Compares the owners of scan `scan`'s pixels now (the merge's keep mask and
// the membership read, not the points) with the store's digest, into
// `changes`. A scan new to the store (`store` none) is read whole, its
// points into changes.added.
void compare_owners(const store::Project& project, const store::StoredScanSummary& stored,
                    const LodScan& scan, const LodStore* store, const LodHeader& header,
                    const ShownPointsSettings& settings, ScanChanges& changes) {
  const auto columns = static_cast<std::size_t>(stored.summary.columns);
  std::vector<std::uint32_t>& added = changes.added_pixels;
  const auto compare = [&](int first, std::span<const std::uint32_t> before,
                           std::span<const std::uint32_t> now) {
    const std::size_t offset = static_cast<std::size_t>(first) * columns;
    bool differs = false, held_changed = false;
    for (std::size_t g = 0; g < now.size(); ++g) {
      if (before[g] == now[g]) continue;
      differs = true;
      const auto pixel = static_cast<std::uint32_t>(offset + g);
      if (!in_store(before[g]) && in_store(now[g])) {
        added.push_back(pixel);
      } else if (in_store(before[g])) {
        held_changed = true;
        // Neighbours in a row mostly share a tile.
        const std::uint64_t tile = tile_of(scan, pixel);
        if (changes.tiles.empty() || changes.tiles.back() != tile) changes.tiles.push_back(tile);
        ++(in_store(now[g]) ? changes.relabelled : changes.removed);
      }
    }
    const int band = first / scan.digest_rows;
    if (differs) changes.bands.emplace_back(band, schema::compress_owners(now));
    if (held_changed) {
      std::vector<std::uint32_t>& owners = changes.now[band];
      owners.assign(now.begin(), now.end());
      // A point leaving the store: kNotShown, whatever the pixel is now.
      for (std::uint32_t& owner : owners) {
        if (!in_store(owner)) owner = kNotShown;
      }
    }
  };
  if (!store) {  // every point new: their owners need the points' validity
    // At most its valid points: room reserved, not touched (no copies as
    // the array grows).
    changes.added.reserve(changes.added.size() + stored.summary.valid_points);
    read_shown_bands(project, stored, scan, header.cube, header.origin, settings,
                     [&](const ShownBand& band) {
                       const std::vector<std::uint32_t> none(band.owners.size(), kNotInModel);
                       compare(band.first_row, none, band.owners);
                       for (std::size_t g = 0; g < band.owners.size(); ++g) {
                         if (in_store(band.owners[g])) changes.added.push_back(band.point(g));
                       }
                     });
    added.clear();
    return;
  }
  std::vector<std::uint32_t> now;
  read_owner_layers(project, stored, scan.digest_rows,
                    [&](int first, int end, const auto& keep, const auto& membership) {
                      const std::vector<std::uint32_t> before =
                          store->owners(scan, first / scan.digest_rows,
                                        static_cast<std::size_t>(end - first) * columns);
                      now = before;
                      for (std::size_t g = 0; g < now.size(); ++g) {
                        if (now[g] != kNotInModel) now[g] = shown_owner(keep, membership, g);
                      }
                      compare(first, before, now);
                    });
  sort_unique(changes.tiles);
}

// Every point the store holds of scan `scan` (one that moved) to be
// removed: the tiles they lie in and their count, from its digest.
void remove_scan(const LodStore& store, const LodScan& scan, const store::StoredScanSummary& stored,
                 ScanChanges& changes) {
  const auto columns = static_cast<std::size_t>(stored.summary.columns);
  for (int first = 0; first < stored.summary.rows; first += scan.digest_rows) {
    const int end = std::min(stored.summary.rows, first + scan.digest_rows);
    const std::vector<std::uint32_t> held = store.owners(
        scan, first / scan.digest_rows, static_cast<std::size_t>(end - first) * columns);
    for (std::size_t g = 0; g < held.size(); ++g) {
      if (!in_store(held[g])) continue;
      changes.tiles.push_back(
          tile_of(scan, static_cast<std::uint32_t>(static_cast<std::size_t>(first) * columns + g)));
      ++changes.removed;
    }
  }
  sort_unique(changes.tiles);
}

// The points of scan `scan` the store must now hold (ScanChanges::added_pixels),
// read with everything the store keeps of them.
void read_added(const store::Project& project, const store::StoredScanSummary& stored,
                const LodScan& scan, const LodHeader& header, const ShownPointsSettings& settings,
                const std::vector<std::uint32_t>& pixels, std::vector<BuildPoint>& added) {
  auto next = pixels.begin();
  read_shown_bands(
      project, stored, scan, header.cube, header.origin, settings, [&](const ShownBand& band) {
        const auto first =
            static_cast<std::uint32_t>(band.first_row) * static_cast<std::uint32_t>(band.columns);
        const auto end = first + static_cast<std::uint32_t>(band.owners.size());
        for (; next != pixels.end() && *next < end; ++next)
          added.push_back(band.point(*next - first));
      });
}

// Whether scan `scan` of the store has a new pose in `now`.
bool has_moved(const LodScan& scan, const store::StoredScanSummary& now) {
  return !now.summary.T_world_scan.matrix().isApprox(scan.T_world_scan.matrix(), 0.0);
}

// Why the store's scans cannot be updated into `scans`; empty when they
// can: the scans it holds are still there, in order, with the points it
// read (a new pose is followed: the scan's points move), and the scans
// that are new or moved lie inside its cube. `sources[k]`: scan k's
// (scan_sources).
std::string why_not_in_place(const store::Project& project,
                             const std::vector<store::StoredScanSummary>& scans,
                             const std::vector<ScanSources>& sources, const LodStore& store) {
  const std::vector<LodScan>& held = store.scans();
  if (held.size() > scans.size()) return "a scan left the project";
  const LodHeader& header = store.header();
  std::uint64_t moving = 0;
  for (std::size_t k = 0; k < scans.size(); ++k) {
    const store::StoredScanSummary& now = scans[k];
    const std::string name = "scan " + std::to_string(now.id) + " (" + now.summary.name + ")";
    if (k < held.size()) {
      if (now.id != held[k].scan_id) return name + " left the project";
      // Another command wrote its layers: the same values (a stage run
      // again on every scan) or new ones.
      if (sources[k].points != held[k].source &&
          scan_points_content(project, now.id) != held[k].content)
        return name + " has new points or geometry";
      if (!has_moved(held[k], now)) continue;
      moving += now.summary.valid_points;
    }
    const auto& bounds = now.summary.bbox_world;
    if (!bounds || !header.cube.quantize(bounds->min() - header.origin) ||
        !header.cube.quantize(bounds->max() - header.origin)) {
      return name + " reaches outside the store's cube";
    }
  }
  // Moving most of the model point by point costs more than a build.
  if (2 * moving > header.points) return "most scans have new poses";
  if (scans.size() > std::size_t{65536}) return "the project has more scans than a store holds";
  return {};
}

// Node `info` with `points` (as stored) as an edit holds it.
EditableNode editable_node(const OctreeCube& cube, const LodNodeInfo& info,
                           const std::vector<LodPoint>& points,
                           const std::vector<std::int64_t>& scan_ids) {
  EditableNode node{info.key, info.leaf, info.points_below, {}};
  const std::array<std::uint64_t, 3> corner = cube.node_corner(info.key);
  node.points.reserve(points.size());
  for (const LodPoint& p : points) node.points.push_back(editable_point(p, corner, scan_ids));
  return node;
}

[[noreturn]] void disagrees(const std::filesystem::path& file, const std::string& problem) {
  schema::damaged(file, "its pixel digest", problem + ": run `scanbench lod --rebuild`");
}

}  // namespace

// Longer than 60 lines, but flat: check, compare, edit, write.
std::optional<LodUpdateResult> update_lod(const store::Project& project,
                                          const LodBuildSettings& settings,
                                          core::Progress& progress, std::string& why_not) {
  const auto start = std::chrono::steady_clock::now();
  LodUpdateResult result;
  result.store = settings.output.empty() ? LodStore::path_for(project.path()) : settings.output;
  if (!std::filesystem::exists(result.store)) {
    why_not = "there is no store yet";
    return std::nullopt;
  }
  const store::Project::ReadSnapshot snapshot = project.read_snapshot();
  std::optional<LodStore> opened;
  try {
    opened.emplace(LodStore::open(result.store));
  } catch (const core::InputError& error) {
    why_not = error.what();
    return std::nullopt;
  }
  const LodStore& store = *opened;
  const LodHeader& header = store.header();
  if (header.octree.max_leaf_points != settings.octree.max_leaf_points) {
    why_not = "the store was built with another leaf size";
    return std::nullopt;
  }
  const std::vector<store::StoredScanSummary> scans = modeling::scans_with_geometry(project);
  // Which commands wrote each scan's layers: read once, used throughout.
  std::vector<ScanSources> sources;
  for (const store::StoredScanSummary& scan : scans)
    sources.push_back(scan_sources(project, scan.id));
  why_not = why_not_in_place(project, scans, sources, store);
  if (!why_not.empty()) return std::nullopt;
  result.from_revision = header.project_revision;
  result.project_revision = project.revision();

  // The scans, the new ones surveyed for their intensity spread.
  std::vector<LodScan> lod_scans = store.scans();
  std::vector<std::int64_t> scan_ids;
  // Scans whose points move: all deleted, then inserted at their new pose.
  std::vector<bool> moved(scans.size(), false);
  for (std::size_t k = 0; k < scans.size(); ++k) {
    scan_ids.push_back(scans[k].id);
    if (k < lod_scans.size()) {
      moved[k] = has_moved(lod_scans[k], scans[k]);
      lod_scans[k].T_world_scan = scans[k].summary.T_world_scan;
      lod_scans[k].source = sources[k].points;
      continue;
    }
    const ScanSurvey survey =
        survey_scan(project, scans[k], header.cube, header.origin, settings.points, {});
    lod_scans.push_back({static_cast<std::uint16_t>(k), scans[k].id, scans[k].summary.name,
                         survey.intensity_low, survey.intensity_high, scans[k].summary.T_world_scan,
                         sources[k].points, "", survey.band_rows, scans[k].summary.columns,
                         scan_points_content(project, scans[k].id)});
    ++result.scans_added;
  }

  // The pixels that changed, from the scans whose owners were written
  // since: their owners alone first, then the points to insert. (On two
  // workers, each with connections of its own, the campus's undo and redo
  // of a commit read in 0.66-0.71 s, against 0.51-0.62 s on one; and the
  // insert of a fifth station took 5.6-5.8 s in all, against 4.7 s on one:
  // the new scan's points, read on a worker, fault pages of their own.)
  std::vector<ScanChanges> changes(scans.size());
  for (std::size_t k = 0; k < scans.size(); ++k) {
    progress.throw_if_cancelled("lod");
    if (sources[k].owners == lod_scans[k].owners_source && !moved[k]) continue;
    lod_scans[k].owners_source = sources[k].owners;
    ++result.scans_read;
    ScanChanges& scan = changes[k];
    if (moved[k]) remove_scan(store, lod_scans[k], scans[k], scan);
    const bool held = k < store.scans().size() && !moved[k];
    compare_owners(project, scans[k], lod_scans[k], held ? &store : nullptr, header,
                   settings.points, scan);
    if (!scan.added_pixels.empty()) {
      read_added(project, scans[k], lod_scans[k], header, settings.points, scan.added_pixels,
                 scan.added);
    }
    progress.update({"lod: compare", k + 1, scans.size(), scans[k].summary.name});
  }
  std::vector<BuildPoint> added;
  std::set<std::uint64_t> tiles;
  std::uint64_t to_relabel = 0, to_remove = 0;
  for (ScanChanges& scan : changes) {
    if (added.empty()) {
      added = std::move(scan.added);
    } else {
      added.insert(added.end(), scan.added.begin(), scan.added.end());
    }
    scan.added = {};
    tiles.insert(scan.tiles.begin(), scan.tiles.end());
    to_relabel += scan.relabelled;
    to_remove += scan.removed;
  }
  result.read_seconds = seconds_since(start);

  // The nodes holding points of the changed tiles, relabelled as read, and
  // the points they hold that the store must no longer.
  std::map<std::uint64_t, LodNodeInfo> infos;
  EditableTree skeleton;
  for (const LodNodeInfo& info : store.nodes()) {
    infos.emplace(info.key.code(), info);
    skeleton.emplace(info.key.code(), EditableNode{info.key, info.leaf, info.points_below, {}});
  }
  std::map<std::uint64_t, std::vector<LodPoint>> points;
  std::set<std::uint64_t> relabelled;
  std::vector<BuildPoint> removed;
  // Reads the nodes of `codes` not read yet: their rows in turn (one
  // connection), their points decoded and relabelled on the workers.
  const auto read_nodes = [&](const auto& codes) {
    std::vector<LodStore::StoredPoints> stored;
    for (const std::uint64_t code : codes) {
      if (!points.count(code)) stored.push_back(store.read_stored_points(infos.at(code).key));
    }
    struct ReadNode {
      std::vector<LodPoint> points;
      std::vector<BuildPoint> removed;
      std::uint64_t relabelled = 0;
    };
    std::vector<ReadNode> read(stored.size());
    core::parallel_for_index(static_cast<int>(stored.size()), settings.threads, [&](int k) {
      const LodStore::StoredPoints& row = stored[static_cast<std::size_t>(k)];
      ReadNode& node = read[static_cast<std::size_t>(k)];
      node.points = store.decode_points(row);
      const std::array<std::uint64_t, 3> corner = header.cube.node_corner(row.key);
      for (LodPoint& p : node.points) {
        const std::optional<std::uint32_t> now =
            moved[p.scan] ? std::nullopt : changes[p.scan].changed_owner(lod_scans[p.scan], p);
        if (!moved[p.scan] && !now) continue;
        if (moved[p.scan] || !in_store(*now)) {
          node.removed.push_back(editable_point(p, corner, scan_ids));
          continue;
        }
        p.object = *now;
        ++node.relabelled;
      }
    });
    std::size_t more = 0;
    for (const ReadNode& node : read) more += node.removed.size();
    removed.reserve(removed.size() + more);
    for (std::size_t k = 0; k < stored.size(); ++k) {
      const std::uint64_t code = stored[k].key.code();
      removed.insert(removed.end(), read[k].removed.begin(), read[k].removed.end());
      read[k].removed = {};
      result.points_relabelled += read[k].relabelled;
      if (read[k].relabelled > 0) relabelled.insert(code);
      points.emplace(code, std::move(read[k].points));
    }
  };
  read_nodes(store.nodes_in_tiles(tiles));
  if (result.points_relabelled != to_relabel || removed.size() != to_remove)
    disagrees(result.store, "names points the store does not hold");
  // And the nodes an edit of the octree reads.
  read_nodes(edit_reads(header.cube, header.octree, skeleton, added, removed));
  result.nodes_read = points.size();
  // Inserts and deletes edit the octree.
  EditableTree tree;
  OctreeEditResult edit;
  if (!added.empty() || !removed.empty()) {
    // Converted on the workers: each node's points get their priorities.
    std::vector<std::pair<std::uint64_t, const std::vector<LodPoint>*>> held;
    for (const auto& [code, node_points] : points) held.emplace_back(code, &node_points);
    std::vector<EditableNode> editable(held.size());
    core::parallel_for_index(static_cast<int>(held.size()), settings.threads, [&](int k) {
      const auto& [code, node_points] = held[static_cast<std::size_t>(k)];
      editable[static_cast<std::size_t>(k)] =
          editable_node(header.cube, infos.at(code), *node_points, scan_ids);
    });
    for (std::size_t k = 0; k < held.size(); ++k)
      tree.emplace(held[k].first, std::move(editable[k]));
    edit =
        edit_octree(header.cube, header.octree, tree, added, removed, scan_ids, settings.threads);
    if (edit.removed_points != removed.size())
      disagrees(result.store, "says the store holds points it does not");
  }
  progress.throw_if_cancelled("lod");
  result.edit_seconds = seconds_since(start) - result.read_seconds;

  // The nodes to write, encoded on the workers (compressing is most of
  // writing them) before the transaction takes the store's write lock:
  // those the edit changed, finished anew, and those only relabelled, in
  // their order.
  std::vector<std::uint64_t> to_write(edit.changed.begin(), edit.changed.end());
  for (const std::uint64_t code : relabelled) {
    if (edit.changed.count(code) || edit.removed.count(code)) continue;
    to_write.push_back(code);
    ++result.nodes_written;
    result.rewritten.push_back(code);
  }
  std::vector<schema::EncodedNode> encoded(to_write.size());
  core::parallel_for_index(static_cast<int>(to_write.size()), settings.threads, [&](int k) {
    const std::uint64_t code = to_write[static_cast<std::size_t>(k)];
    schema::EncodedNode& out = encoded[static_cast<std::size_t>(k)];
    if (edit.changed.count(code)) {
      EditableNode& node = tree.at(code);
      out = schema::encode_node(
          header.cube, lod_scans,
          finish_node(header.cube,
                      Subtree{node.key, node.leaf, node.points_below, std::move(node.points)}));
    } else {
      const LodNodeInfo& info = infos.at(code);
      out = schema::encode_node(header.cube, lod_scans,
                                BuiltNode{info.key, info.leaf, info.points_below,
                                          std::move(points.at(code)), info.level_ends});
    }
  });

  // Written in one transaction.
  sqlite3* db = schema::connect(result.store, SQLITE_OPEN_READWRITE);
  const std::unique_ptr<sqlite3, decltype(&sqlite3_close)> closing(db, &sqlite3_close);
  const std::string name = result.store.string();
  store::sqlite::execute(db, "BEGIN IMMEDIATE", name);
  try {
    {
      Statement revision(db, "SELECT project_revision FROM lod_header", name);
      if (!revision.step() || revision.column_int(0) != header.project_revision) {
        store::sqlite::execute(db, "ROLLBACK", name);
        why_not = "another process updated the store meanwhile";
        return std::nullopt;
      }
    }
    for (const std::uint64_t code : edit.removed) {
      for (const char* sql : {"DELETE FROM lod_node_tiles WHERE code = ?1",
                              "DELETE FROM lod_nodes WHERE code = ?1"}) {
        Statement remove(db, sql, name);
        remove.bind_int(1, static_cast<std::int64_t>(code)).run();
      }
    }
    for (const schema::EncodedNode& node : encoded) schema::put_node(db, name, node);
    for (const LodScan& scan : lod_scans) schema::put_scan(db, name, scan);
    for (std::size_t k = 0; k < changes.size(); ++k) {
      for (const auto& [band, owners] : changes[k].bands)
        schema::put_compressed_owners(db, name, static_cast<std::uint16_t>(k), band, owners);
    }
    result.points = header.points + added.size() - removed.size();
    result.nodes = header.nodes + edit.changed.size() - edit.removed.size();
    for (const std::uint64_t code : edit.changed) result.nodes -= infos.count(code);
    Statement update(db, "UPDATE lod_header SET project_revision = ?1, points = ?2, nodes = ?3",
                     name);
    update.bind_int(1, result.project_revision)
        .bind_int(2, static_cast<std::int64_t>(result.points))
        .bind_int(3, static_cast<std::int64_t>(result.nodes))
        .run();
  } catch (...) {
    sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
  store::sqlite::execute(db, "COMMIT", name);
  result.points_added = added.size();
  result.points_removed = removed.size();
  result.nodes_written += edit.changed.size();
  result.nodes_removed = edit.removed.size();
  result.rewritten.insert(result.rewritten.end(), edit.changed.begin(), edit.changed.end());
  result.rewritten.insert(result.rewritten.end(), edit.removed.begin(), edit.removed.end());
  result.seconds = seconds_since(start);
  result.write_seconds = result.seconds - result.read_seconds - result.edit_seconds;
  return result;
}

LodRefreshResult refresh_lod(const store::Project& project, const LodBuildSettings& settings,
                             core::Progress& progress) {
  LodRefreshResult refresh;
  if (settings.output.empty()) {
    if (const std::optional<std::filesystem::path> current = current_lod_store(project)) {
      const LodHeader header = LodStore::open(*current).header();
      refresh.updated = LodUpdateResult{};
      refresh.updated->store = *current;
      refresh.updated->from_revision = refresh.updated->project_revision = header.project_revision;
      refresh.updated->points = header.points;
      refresh.updated->nodes = header.nodes;
      return refresh;
    }
  }
  std::string why_not;
  refresh.updated = update_lod(project, settings, progress, why_not);
  if (!refresh.updated) {
    refresh.why_built = why_not;
    refresh.built = build_lod(project, settings, progress);
  }
  return refresh;
}

}  // namespace scanbench::lod

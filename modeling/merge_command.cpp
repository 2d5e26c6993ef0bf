#include "modeling/merge_command.hpp"

#include <chrono>
#include <map>

#include "core/timing.hpp"
#include "modeling/command_json.hpp"
#include "modeling/scan_cache.hpp"
#include "modeling/scan_overlaps.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::modeling {
namespace {

constexpr const char* kStage = "merge";

// The merge's scans: what it compares only, two kept in memory beyond the
// pair in hand, the others parked in a temporary file until the plan
// brings them back.
const ScanCacheSettings kMergeCache{.form = ScanForm::kMerge, .spill = true, .max_kept = 2};

// The streamed merge: scan b is compared with each earlier scan a whose
// bounds reach it, both ways, while both are in hand; a scan's decision is
// final after its last pair. Each scan is thus compared with the others in
// list order, as merge_by_sampling_rate does: the keep masks and counts are
// the same, but for decided_by_bound, which counts the pairs compared only.
class StreamedMerge {
 public:
  StreamedMerge(const store::Project& project, const registration::MergeSettings& settings,
                std::uint64_t memory_limit, core::Progress& progress)
      : scans_(scans_with_geometry(project)),
        pairs_(overlapping_pairs(scans_)),
        settings_(settings),
        last_pair_(scans_.size()),
        cache_(project, memory_limit, settings.threads, kStage, progress, kMergeCache),
        progress_(progress) {
    cache_.plan(plan());
  }

  MergeCommandResult run() {
    out_.scans.resize(scans_.size());
    masks_.resize(scans_.size());
    auto pair = pairs_.begin();
    for (int b = 0; b < static_cast<int>(scans_.size()); ++b) {
      const std::shared_ptr<const LoadedScan> second = cache_.get(id(b));
      const registration::MergeOperand operand_b = operand(b, *second);
      open_[b] = registration::start_merge(second->prepared);
      for (; pair != pairs_.end() && pair->second == b; ++pair) {
        const std::shared_ptr<const LoadedScan> first = cache_.get(id(pair->first));
        const registration::MergeOperand operand_a = operand(pair->first, *first);
        const auto start = std::chrono::steady_clock::now();
        registration::merge_with(open_.at(b), operand_b, operand_a, settings_);
        registration::merge_with(open_.at(pair->first), operand_a, operand_b, settings_);
        out_.seconds += core::seconds_since(start);
        if (last_pair_[static_cast<std::size_t>(pair->first)] == b) finish(pair->first, *first);
      }
      if (last_pair_[static_cast<std::size_t>(b)] == b) finish(b, *second);
      progress_.update({kStage, static_cast<std::size_t>(b) + 1, scans_.size(),
                        "merged " + scans_[static_cast<std::size_t>(b)].summary.name});
    }
    return std::move(out_);
  }

  std::vector<store::EncodedLayer>& masks() { return masks_; }
  std::int64_t id(int k) const { return scans_[static_cast<std::size_t>(k)].id; }

 private:
  // Scan b, then the earlier scans it pairs with, for every b; and for each
  // scan the b of its last pair (itself when it has none later).
  std::vector<std::int64_t> plan() {
    for (int k = 0; k < static_cast<int>(scans_.size()); ++k)
      last_pair_[static_cast<std::size_t>(k)] = k;
    for (const ScanPair& pair : pairs_)
      last_pair_[static_cast<std::size_t>(pair.first)] = pair.second;
    std::vector<std::int64_t> order;
    for (const int k : pair_pass_order(pairs_, static_cast<int>(scans_.size()), true))
      order.push_back(id(k));
    return order;
  }

  registration::MergeOperand operand(int k, const LoadedScan& loaded) {
    auto [found, fresh] = footprint_per_m_.try_emplace(k, 0.0f);
    if (fresh && settings_.bound_coarser_scans)
      found->second = registration::max_footprint_per_m(loaded.prepared);
    return {&loaded.prepared, k, loaded.scan.T_world_scan, found->second};
  }

  void finish(int k, const LoadedScan& loaded) {
    registration::MergeScanResult result = std::move(open_.at(k));
    open_.erase(k);
    registration::finish_merge(result, loaded.prepared);
    out_.points += result.in_model;
    masks_[static_cast<std::size_t>(k)] = store::encode_layer<std::uint8_t>(
        store::layer::kKeep, store::ElementType::kU8, result.keep);
    result.keep.clear();
    result.keep.shrink_to_fit();
    out_.scans[static_cast<std::size_t>(k)] = {id(k), loaded.scan.name, std::move(result)};
  }

  std::vector<store::StoredScanSummary> scans_;
  std::vector<ScanPair> pairs_;
  registration::MergeSettings settings_;
  std::vector<int> last_pair_;
  ScanCache cache_;
  core::Progress& progress_;
  std::map<int, registration::MergeScanResult> open_;  // scans whose pairs are not all done
  std::map<int, float> footprint_per_m_;
  std::vector<store::EncodedLayer> masks_;
  MergeCommandResult out_;
};

}  // namespace

MergeCommandResult merge_project(store::Project& project,
                                 const registration::MergeSettings& settings,
                                 core::Progress& progress,
                                 std::optional<std::uint64_t> memory_limit) {
  const std::int64_t revision = project.revision();
  StreamedMerge merge(project, settings, memory_limit_or_default(memory_limit), progress);
  MergeCommandResult out = merge.run();
  progress.throw_if_cancelled(kStage);

  store::Project::Edit edit = project.begin_command(kStage, settings_to_json(settings), revision);
  out.command_id = edit.command_id();
  for (std::size_t k = 0; k < out.scans.size(); ++k)
    project.put_layer(edit, out.scans[k].id, merge.masks()[k]);
  edit.commit(result_json(out));
  return out;
}

}  // namespace scanbench::modeling

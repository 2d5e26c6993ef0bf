#include "modeling/selection_tools.hpp"

#include <algorithm>
#include <cassert>
#include <set>
#include <utility>

#include "core/errors.hpp"

namespace scanbench::modeling {

namespace {

// The project's scans now: a scan whose import was undone keeps nothing.
std::set<std::int64_t> scan_ids(const store::Project& project) {
  std::set<std::int64_t> out;
  for (const store::StoredScanSummary& stored : project.scans()) out.insert(stored.id);
  return out;
}

}  // namespace

void SelectionTools::draw_on(std::int64_t scan_id) {
  assert((!scan_ || *scan_ == scan_id) && "lines of two scans at once: clear() between them");
  scan_ = scan_id;
}

void SelectionTools::set_lasso(std::int64_t scan_id, segmentation::Polyline lasso) {
  draw_on(scan_id);
  lasso_ = std::move(lasso);
  lasso_closed_ = true;
}

void SelectionTools::add_barrier(std::int64_t scan_id, segmentation::Polyline barrier) {
  draw_on(scan_id);
  barriers_.push_back(std::move(barrier));
  drawing_barrier_ = false;
}

void SelectionTools::add_lasso_vertex(std::int64_t scan_id, const Eigen::Vector2d& xy) {
  draw_on(scan_id);
  if (lasso_closed_) {
    lasso_.clear();
    lasso_closed_ = false;
  }
  lasso_.push_back(xy);
}

void SelectionTools::add_barrier_vertex(std::int64_t scan_id, const Eigen::Vector2d& xy) {
  draw_on(scan_id);
  if (!drawing_barrier_) barriers_.emplace_back();
  drawing_barrier_ = true;
  barriers_.back().push_back(xy);
}

bool SelectionTools::close_lasso() {
  if (lasso_.size() < 3) return false;
  lasso_closed_ = true;
  return true;
}

void SelectionTools::end_barrier() {
  drawing_barrier_ = false;
}

void SelectionTools::clear() {
  scan_.reset();
  lasso_.clear();
  lasso_closed_ = false;
  barriers_.clear();
  drawing_barrier_ = false;
}

SelectSettings SelectionTools::select_at(std::int64_t scan_id, const Eigen::Vector2d& xy,
                                         SelectMode mode,
                                         const segmentation::GrowSettings& grow) const {
  assert((!scan_ || *scan_ == scan_id) && "a lasso or barriers of another scan");
  SelectSettings settings;
  settings.scan_id = scan_id;
  const segmentation::GridPixel pixel = segmentation::nearest_pixel(xy);
  settings.seed_row = pixel.row;
  settings.seed_col = pixel.col;
  settings.mode = mode;
  settings.grow = grow;
  if (lasso_closed_) settings.constraints.lasso = lasso_;
  settings.constraints.barriers = barriers_;
  return settings;
}

const segmentation::PixelSet& SelectionTools::selection(std::int64_t scan_id) const {
  static const segmentation::PixelSet kNone;
  const auto found = selections_.find(scan_id);
  return found == selections_.end() ? kNone : found->second;
}

segmentation::PixelSet& SelectionTools::selection_of(const store::Project& project,
                                                     std::int64_t scan_id) {
  auto found = selections_.find(scan_id);
  if (found == selections_.end()) {
    found = selections_.emplace(scan_id, kept_selection(project, scan_id)).first;
  }
  return found->second;
}

void SelectionTools::open_scan(const store::Project& project, std::int64_t scan_id) {
  static_cast<void>(selection_of(project, scan_id));
}

void SelectionTools::record(Step step) {
  for (const ScanChange& change : step) touched_.insert(change.scan_id);
  done_.push_back(std::move(step));
  if (done_.size() > kMaxSelectionSteps) done_.pop_front();
  undone_.clear();
}

SelectResult SelectionTools::select(const store::Project& project, const SelectSettings& settings) {
  segmentation::PixelSet& selection = selection_of(project, settings.scan_id);
  const segmentation::PixelSet before = selection;
  const SelectResult result = select_region(project, settings, selection);
  if (!result.seed_open) return result;
  if (settings.mode != SelectMode::kSubtract) grown_with_[settings.scan_id] = settings.grow;
  record({{settings.scan_id, segmentation::subtract(selection, before),
           segmentation::subtract(before, selection)}});
  return result;
}

std::size_t SelectionTools::select_pixels(
    const store::Project& project, const std::map<std::int64_t, segmentation::PixelSet>& region,
    SelectMode mode) {
  std::map<std::int64_t, std::size_t> grid_pixels;
  for (const store::StoredScanSummary& stored : project.scans())
    grid_pixels[stored.id] = static_cast<std::size_t>(stored.summary.rows) * stored.summary.columns;
  for (const auto& [scan_id, pixels] : region) {
    const auto grid = grid_pixels.find(scan_id);
    if (grid == grid_pixels.end())
      throw core::InputError(project.path().string(), {},
                             "scan " + std::to_string(scan_id) + ": no such scan");
    if (!pixels.empty() && pixels.back() >= grid->second)
      throw core::InputError(
          project.path().string(), {},
          "scan " + std::to_string(scan_id) + ": the selection has a pixel outside the grid");
  }
  static const segmentation::PixelSet kNone;
  const auto region_of = [&](std::int64_t scan_id) -> const segmentation::PixelSet& {
    const auto found = region.find(scan_id);
    return found == region.end() ? kNone : found->second;
  };
  Step step;
  std::size_t selected = 0;
  for (const auto& [scan_id, pixels] : grid_pixels) {
    if (mode != SelectMode::kReplace && region.count(scan_id) == 0) {
      selected += selection(scan_id).size();
      continue;
    }
    segmentation::PixelSet& now = selection_of(project, scan_id);
    const segmentation::PixelSet before = now;
    switch (mode) {
      case SelectMode::kReplace:
        now = region_of(scan_id);
        break;
      case SelectMode::kAdd:
        now = segmentation::unite(now, region_of(scan_id));
        break;
      case SelectMode::kSubtract:
        now = segmentation::subtract(now, region_of(scan_id));
        break;
    }
    selected += now.size();
    if (now != before)
      step.push_back(
          {scan_id, segmentation::subtract(now, before), segmentation::subtract(before, now)});
  }
  if (!step.empty()) record(std::move(step));
  return selected;
}

std::map<std::int64_t, segmentation::PixelSet> SelectionTools::selections() const {
  std::map<std::int64_t, segmentation::PixelSet> out;
  for (const auto& [scan_id, selection] : selections_) {
    if (!selection.empty()) out.emplace(scan_id, selection);
  }
  return out;
}

std::size_t SelectionTools::selected_pixels() const {
  std::size_t total = 0;
  for (const auto& [scan_id, selection] : selections_) total += selection.size();
  return total;
}

std::size_t SelectionTools::selected_scans() const {
  return static_cast<std::size_t>(
      std::count_if(selections_.begin(), selections_.end(),
                    [](const auto& entry) { return !entry.second.empty(); }));
}

CommitSettings SelectionTools::commit_of(std::int64_t scan_id, std::string name,
                                         std::optional<std::int64_t> parent) const {
  CommitSettings settings;
  settings.scan_id = scan_id;
  settings.name = std::move(name);
  settings.parent = parent;
  if (const auto grown = grown_with_.find(scan_id); grown != grown_with_.end())
    settings.grow = grown->second;
  return settings;
}

void SelectionTools::committed(std::int64_t command_id, const std::vector<std::int64_t>& scans) {
  command_ran();
  std::map<std::int64_t, segmentation::PixelSet>& taken = committed_[command_id];
  for (const std::int64_t scan_id : scans) {
    taken[scan_id] = std::move(selections_[scan_id]);
    selections_[scan_id].clear();
    touched_.insert(scan_id);
  }
  if (committed_.size() > kMaxCommitsRemembered) committed_.erase(committed_.begin());
}

NodeCommandResult SelectionTools::commit(store::Project& project, const CommitSettings& settings) {
  const NodeCommandResult result =
      commit_selection(project, settings, selection_of(project, settings.scan_id));
  committed(result.command_id, {settings.scan_id});
  return result;
}

NodeCommandResult SelectionTools::commit_all(store::Project& project, std::int64_t shown_scan,
                                             std::string name, std::optional<std::int64_t> parent) {
  const std::map<std::int64_t, segmentation::PixelSet> all = selections();
  CommitSettings settings = commit_of(shown_scan, std::move(name), parent);
  if (all.count(shown_scan) == 0) settings.grow.reset();
  const NodeCommandResult result = commit_selections(project, settings, all);
  std::vector<std::int64_t> scans;
  for (const auto& [scan_id, selection] : all) scans.push_back(scan_id);
  committed(result.command_id, scans);
  return result;
}

bool SelectionTools::undo_selection() {
  if (done_.empty()) return false;
  for (const ScanChange& change : done_.back()) {
    segmentation::PixelSet& selection = selections_[change.scan_id];
    selection =
        segmentation::unite(segmentation::subtract(selection, change.added), change.removed);
  }
  undone_.push_back(std::move(done_.back()));
  done_.pop_back();
  return true;
}

bool SelectionTools::redo_selection() {
  if (undone_.empty()) return false;
  for (const ScanChange& change : undone_.back()) {
    segmentation::PixelSet& selection = selections_[change.scan_id];
    selection =
        segmentation::unite(segmentation::subtract(selection, change.removed), change.added);
  }
  done_.push_back(std::move(undone_.back()));
  undone_.pop_back();
  return true;
}

void SelectionTools::command_ran() {
  done_.clear();
  undone_.clear();
}

void SelectionTools::reread_untouched(const store::Project& project) {
  const std::set<std::int64_t> scans = scan_ids(project);
  for (auto& [scan_id, selection] : selections_) {
    if (touched_.count(scan_id) != 0) continue;
    selection =
        scans.count(scan_id) != 0 ? kept_selection(project, scan_id) : segmentation::PixelSet{};
  }
}

void SelectionTools::command_undone(const store::Project& project, std::int64_t command_id) {
  command_ran();
  reread_untouched(project);
  const auto commit = committed_.find(command_id);
  if (commit == committed_.end()) return;
  for (const auto& [scan_id, selection] : commit->second) selections_[scan_id] = selection;
}

void SelectionTools::command_redone(const store::Project& project, std::int64_t command_id) {
  command_ran();
  reread_untouched(project);
  const auto commit = committed_.find(command_id);
  if (commit == committed_.end()) return;
  for (const auto& [scan_id, selection] : commit->second) selections_[scan_id].clear();
}

std::map<std::int64_t, segmentation::PixelSet> SelectionTools::unkept(
    const store::Project& project) const {
  const std::set<std::int64_t> scans = scan_ids(project);
  std::map<std::int64_t, segmentation::PixelSet> changed;
  for (const std::int64_t scan_id : touched_) {
    const segmentation::PixelSet& now = selection(scan_id);
    if (scans.count(scan_id) != 0 && kept_selection(project, scan_id) != now)
      changed.emplace(scan_id, now);
  }
  return changed;
}

SelectionTools::Kept SelectionTools::keep(store::Project& project, bool spare_redo_chain) {
  const std::map<std::int64_t, segmentation::PixelSet> changed = unkept(project);
  if (changed.empty()) return {};
  if (spare_redo_chain) {
    for (const store::CommandRecord& c : project.history()) {
      if (c.state == store::CommandState::kUndone) return {0, true};
    }
  }
  const std::int64_t command_id = keep_selections(project, changed);
  command_ran();
  return {command_id, false};
}

}  // namespace scanbench::modeling

#include "modeling/selection_tools.hpp"

#include <cassert>
#include <set>
#include <utility>

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

SelectResult SelectionTools::select(const store::Project& project, const SelectSettings& settings) {
  segmentation::PixelSet& selection = selection_of(project, settings.scan_id);
  const segmentation::PixelSet before = selection;
  const SelectResult result = select_region(project, settings, selection);
  if (!result.seed_open) return result;
  if (settings.mode != SelectMode::kSubtract) grown_with_[settings.scan_id] = settings.grow;
  touched_.insert(settings.scan_id);
  done_.push_back({settings.scan_id, segmentation::subtract(selection, before),
                   segmentation::subtract(before, selection)});
  if (done_.size() > kMaxSelectionSteps) done_.pop_front();
  undone_.clear();
  return result;
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

NodeCommandResult SelectionTools::commit(store::Project& project, const CommitSettings& settings) {
  segmentation::PixelSet& selection = selection_of(project, settings.scan_id);
  const NodeCommandResult result = commit_selection(project, settings, selection);
  command_ran();
  committed_[result.command_id] = {settings.scan_id, std::move(selection)};
  if (committed_.size() > kMaxCommitsRemembered) committed_.erase(committed_.begin());
  selection.clear();
  touched_.insert(settings.scan_id);
  return result;
}

bool SelectionTools::undo_selection() {
  if (done_.empty()) return false;
  const Step& step = done_.back();
  segmentation::PixelSet& selection = selections_[step.scan_id];
  selection = segmentation::unite(segmentation::subtract(selection, step.added), step.removed);
  undone_.push_back(std::move(done_.back()));
  done_.pop_back();
  return true;
}

bool SelectionTools::redo_selection() {
  if (undone_.empty()) return false;
  const Step& step = undone_.back();
  segmentation::PixelSet& selection = selections_[step.scan_id];
  selection = segmentation::unite(segmentation::subtract(selection, step.removed), step.added);
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
  if (commit != committed_.end()) selections_[commit->second.first] = commit->second.second;
}

void SelectionTools::command_redone(const store::Project& project, std::int64_t command_id) {
  command_ran();
  reread_untouched(project);
  const auto commit = committed_.find(command_id);
  if (commit != committed_.end()) selections_[commit->second.first].clear();
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

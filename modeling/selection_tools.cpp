#include "modeling/selection_tools.hpp"

#include <cassert>
#include <utility>

namespace scanbench::modeling {

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

void SelectionTools::grew(const SelectSettings& settings) {
  if (settings.mode != SelectMode::kSubtract) grown_with_[settings.scan_id] = settings.grow;
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

}  // namespace scanbench::modeling

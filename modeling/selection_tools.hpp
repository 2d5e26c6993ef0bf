// The segmentation tools between one click and the next (seed 004 §4.1,
// Fig. 2): a lasso and barrier lines drawn on one scan, and the last seed,
// in image coordinates (x = column, y = row, pixel centres at integers:
// segmentation/constraints.hpp). The CLI's segment scripts and the
// workbench each keep one, and a click becomes select_region's settings
// through it, so that both put a click on the same pixel.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <optional>
#include <vector>

#include "modeling/selection_commands.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::modeling {

class SelectionTools {
 public:
  // The scan the lasso and barriers were drawn on; none while there are none.
  std::optional<std::int64_t> scan() const { return scan_; }
  const segmentation::Polyline& lasso() const { return lasso_; }
  bool lasso_closed() const { return lasso_closed_; }
  const std::vector<segmentation::Polyline>& barriers() const { return barriers_; }
  const std::optional<Eigen::Vector2d>& seed() const { return seed_; }

  // Whole lines on scan `scan_id` (a script's ops): a closed lasso in place
  // of any other, or one more barrier. Asserts they are on the scan the
  // others were drawn on (the caller refuses otherwise).
  void set_lasso(std::int64_t scan_id, segmentation::Polyline lasso);
  void add_barrier(std::int64_t scan_id, segmentation::Polyline barrier);

  // Vertex by vertex (the workbench's clicks): a vertex of the lasso (a
  // closed one starts over) or of the barrier being drawn (a new one after
  // end_barrier). As set_lasso for the scan.
  void add_lasso_vertex(std::int64_t scan_id, const Eigen::Vector2d& xy);
  void add_barrier_vertex(std::int64_t scan_id, const Eigen::Vector2d& xy);
  // Closes the lasso; false (and it stays open) with fewer than 3 vertices.
  bool close_lasso();
  void end_barrier();

  // The seed later grows start from when they give none.
  void set_seed(const Eigen::Vector2d& xy) { seed_ = xy; }

  // No lasso, no barriers (the seed stays).
  void clear();

  // select_region's settings for a seed at image point `xy` of scan
  // `scan_id`: the nearest pixel, the lasso when it is closed, the barriers.
  // Asserts the lasso and barriers, if any, were drawn on `scan_id` (the
  // caller refuses or clears them otherwise).
  SelectSettings select_at(std::int64_t scan_id, const Eigen::Vector2d& xy, SelectMode mode,
                           const segmentation::GrowSettings& grow) const;
  // select_region ran `settings` and its seed grew: a grow that replaced or
  // added to the selection is remembered for the scan's commit.
  void grew(const SelectSettings& settings);

  // commit_selection's settings for the selection of scan `scan_id`: it
  // grows on in the other scans with the settings of the last grow that
  // replaced or added to it in this session (none before any).
  CommitSettings commit_of(std::int64_t scan_id, std::string name,
                           std::optional<std::int64_t> parent) const;

 private:
  void draw_on(std::int64_t scan_id);

  std::optional<std::int64_t> scan_;
  segmentation::Polyline lasso_;
  bool lasso_closed_ = false;
  std::vector<segmentation::Polyline> barriers_;
  bool drawing_barrier_ = false;
  std::optional<Eigen::Vector2d> seed_;
  std::map<std::int64_t, segmentation::GrowSettings> grown_with_;  // per scan
};

}  // namespace scanbench::modeling

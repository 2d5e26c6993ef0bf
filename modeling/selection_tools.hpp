// The segmentation tools between one click and the next (seed 004 §4.1,
// Fig. 2): a lasso and barrier lines drawn on one scan, and the last seed,
// in image coordinates (x = column, y = row, pixel centres at integers:
// segmentation/constraints.hpp), and the selection of each scan. The CLI's
// segment scripts and the workbench each keep one, and a click becomes
// select_region's settings through it, so that both put a click on the
// same pixel.
//
// Selections are session state: a grow changes them here and writes
// nothing, so a click neither ends the project's redo chain nor collides
// with another process's work. Undo takes the grows back one by one until
// the last command; undoing a commit brings its selection back. keep()
// stores them in the project, when the session ends or on request, and the
// next session starts from them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "modeling/selection_commands.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/pixel_set.hpp"
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
  // ---- The selections ---------------------------------------------------
  // The selection of scan `scan_id`: the one kept in the project until
  // this session changes it (read by open_scan, select and commit).
  const segmentation::PixelSet& selection(std::int64_t scan_id) const;
  // Reads the selection kept for scan `scan_id`, unless this session
  // already has the scan's.
  void open_scan(const store::Project& project, std::int64_t scan_id);

  // Grows `settings` (from select_at) into the scan's selection
  // (select_region). A seed that grows makes one step undo_selection takes
  // back; a grow that replaced or added to the selection is remembered for
  // the scan's commit.
  SelectResult select(const store::Project& project, const SelectSettings& settings);

  // Combines `region` (scan id → pixels, ascending: a selection drawn in
  // the 3D view spans every scan it reaches) with the selections by `mode`,
  // as one step undo_selection takes back: replace makes it the selection
  // of every scan of the project (others' become empty), add and subtract
  // change only the scans it names. Pixels outside a scan's grid are
  // refused (core::InputError) before anything changes. Returns the
  // pixels selected in all scans afterwards.
  std::size_t select_pixels(const store::Project& project,
                            const std::map<std::int64_t, segmentation::PixelSet>& region,
                            SelectMode mode);
  // Every scan's selection that is not empty, by scan id (those this
  // session has read: open_scan, select, select_pixels).
  std::map<std::int64_t, segmentation::PixelSet> selections() const;
  // Their pixels in all, and the scans they are in.
  std::size_t selected_pixels() const;
  std::size_t selected_scans() const;

  // commit_selection's settings for the selection of scan `scan_id`: it
  // grows on in the other scans with the settings of the last grow that
  // replaced or added to it in this session (none before any).
  CommitSettings commit_of(std::int64_t scan_id, std::string name,
                           std::optional<std::int64_t> parent) const;
  // Commits the selection of settings.scan_id (commit_selection); it is
  // then empty, until the command is undone (command_undone).
  NodeCommandResult commit(store::Project& project, const CommitSettings& settings);
  // Commits every scan's selection (selections()) as one object
  // (commit_selections), growing on as the grows of the shown scan
  // `shown_scan` did when it has a selection (none: only the surfaces the
  // selections cover); they are then empty, until the command is undone.
  NodeCommandResult commit_all(store::Project& project, std::int64_t shown_scan, std::string name,
                               std::optional<std::int64_t> parent);

  // ---- Undo and redo ------------------------------------------------------
  // Takes back the newest grow since the last command, or makes the newest
  // one taken back again; false when there is none. The newest
  // kMaxSelectionSteps grows are kept.
  bool undo_selection();
  bool redo_selection();
  // Grows since the last command (or undo): redoing the project's commands
  // would pass over them (the caller refuses, as a new command ends a
  // redo chain).
  bool grown_since_command() const { return !done_.empty(); }
  // The caller ran another command: the grows before it are no longer
  // taken back one by one.
  void command_ran();
  // The caller undid or redid command `command_id` in the project: the
  // selection a commit took comes back, or goes again, and the scans this
  // session has not changed show what the project now keeps.
  void command_undone(const store::Project& project, std::int64_t command_id);
  void command_redone(const store::Project& project, std::int64_t command_id);

  // ---- Keeping them -----------------------------------------------------
  // The selections this session changed that differ from what the project
  // keeps (a scan whose import was undone keeps nothing).
  std::map<std::int64_t, segmentation::PixelSet> unkept(const store::Project& project) const;
  struct Kept {
    std::int64_t command_id = 0;  // 0: nothing was kept
    bool held_back = false;       // kept nothing, to spare the redo chain
  };
  // Stores unkept(project) as one command (keep_selections). Like every
  // new command it ends the project's redo chain: with `spare_redo_chain`
  // (when a session ends by itself) nothing is kept while there is one.
  Kept keep(store::Project& project, bool spare_redo_chain);

  static constexpr std::size_t kMaxSelectionSteps = 200;
  static constexpr std::size_t kMaxCommitsRemembered = 32;

 private:
  void draw_on(std::int64_t scan_id);
  segmentation::PixelSet& selection_of(const store::Project& project, std::int64_t scan_id);
  // Reads again the kept selections of the scans this session has not changed.
  void reread_untouched(const store::Project& project);

  // One change of a scan's selection: the pixels it added and removed.
  struct ScanChange {
    std::int64_t scan_id = 0;
    segmentation::PixelSet added;
    segmentation::PixelSet removed;
  };
  // One step: a grow changes one scan, a 3D selection several.
  using Step = std::vector<ScanChange>;
  void record(Step step);
  // Remembers the selections commit `command_id` took, and empties them.
  void committed(std::int64_t command_id, const std::vector<std::int64_t>& scans);

  std::optional<std::int64_t> scan_;
  segmentation::Polyline lasso_;
  bool lasso_closed_ = false;
  std::vector<segmentation::Polyline> barriers_;
  bool drawing_barrier_ = false;
  std::optional<Eigen::Vector2d> seed_;
  std::map<std::int64_t, segmentation::GrowSettings> grown_with_;  // per scan
  std::map<std::int64_t, segmentation::PixelSet> selections_;      // the scans' read so far
  std::set<std::int64_t> touched_;  // scans whose selection this session changed
  std::deque<Step> done_;           // grows since the last command, oldest first
  std::vector<Step> undone_;
  // By commit command, the newest kMaxCommitsRemembered: the selections it
  // took, by scan.
  std::map<std::int64_t, std::map<std::int64_t, segmentation::PixelSet>> committed_;
};

}  // namespace scanbench::modeling

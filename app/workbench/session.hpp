// The workbench's state apart from its window: the open project, the scan in
// the panoramic view with its layers, the tools (seed, lasso, barrier), and
// the actions, each through the same commands the CLI's segment script and
// recolor issue (modeling/selection_commands.hpp, modeling/tree_commands.hpp,
// modeling/color_commands.hpp), so every action is one journal entry that
// Ctrl+Z takes back. The selection is session state (SelectionTools): a grow
// writes nothing, and Ctrl+Z takes grows back before commands. No ImGui here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/scan.hpp"
#include "modeling/color_commands.hpp"
#include "modeling/measurements.hpp"
#include "modeling/selection_commands.hpp"
#include "modeling/selection_tools.hpp"
#include "modeling/store/project.hpp"
#include "render/panorama_picture.hpp"
#include "segmentation/constraints.hpp"
#include "segmentation/segmentation_grid.hpp"

namespace scanbench::app::workbench {

// The brush selects in the 3D view only; the lasso draws in either view.
enum class Tool { kSeed, kLasso, kBarrier, kBrush };

class Session {
 public:
  // Opens the project (Project::open, or open_read_only: throws as they do)
  // and its first scan, if it has any: the workbench opens in every state of
  // a project. Read-only, every command is refused before it computes.
  Session(const std::filesystem::path& project, bool read_only);

  // Whether `file` must be opened read-only: it or its folder cannot be
  // written, or no one has write permission on it (root included).
  static bool cannot_write(const std::filesystem::path& file);
  bool read_only() const { return read_only_; }

  store::Project& project() { return project_; }
  const std::vector<store::StoredScanSummary>& scans() const { return scans_; }
  std::int64_t scan_id() const { return scan_id_; }
  // The scan shown: empty (0 × 0, id 0) while the project has none.
  const acquisition::Scan& scan() const { return scan_; }
  bool has_scan() const { return scan_id_ != 0; }
  void open_scan(std::int64_t id);
  // What the panoramic tools lack, and how to get it: no scans, a scan
  // without a range image (an unstructured cloud), or no geometry for the
  // scan shown; empty when nothing is missing.
  std::string missing() const;
  // Whether the scan shown has a range image for the panoramic view and
  // its tools (an unstructured cloud has none: acquisition::Scan::
  // is_scattered).
  bool has_grid() const { return has_scan() && !scan_.is_scattered(); }

  // ---- Tools (image coordinates: x = column, y = row, pixel centres at
  // integers: segmentation/constraints.hpp) --------------------------------
  Tool tool = Tool::kSeed;
  segmentation::Channel channel = segmentation::Channel::kNormal;
  double tolerance = segmentation::default_grow_settings(segmentation::Channel::kNormal).tolerance;
  modeling::SelectMode mode = modeling::SelectMode::kReplace;
  const segmentation::Polyline& lasso() const { return tools_.lasso(); }
  bool lasso_closed() const { return tools_.lasso_closed(); }
  const std::vector<segmentation::Polyline>& barriers() const { return tools_.barriers(); }
  // A click of the current tool at (x, y): a seed grows a region, a lasso
  // or barrier gets a vertex.
  void click(double x, double y);
  // Closes the lasso (≥ 3 vertices) or ends the barrier being drawn.
  void finish_polyline();
  void clear_constraints();
  // The selection's pixels in all scans, and the scans it is in (a 3D
  // selection spans several; the panorama shows the shown scan's part).
  std::size_t selected_pixels() const { return selected_; }
  std::size_t selected_scans() const { return selected_scans_; }
  // A selection made in the 3D view (render::LodRenderer::select): pixels
  // by scan id, combined with the selection by `mode` as one step Ctrl+Z
  // takes back. `what` names the tool for the status ("lasso").
  void select_pixels(const std::map<std::int64_t, std::vector<std::uint32_t>>& region,
                     const std::string& what);
  // Keeps the selections this session changed in the project, as one
  // command (modeling::SelectionTools::keep): on request, and `at_close`,
  // when the session ends, unless that would end the redo chain. False
  // (and status()) when it failed. Read-only, nothing is kept.
  bool keep_selections(bool at_close = false);

  // ---- Measuring in the panorama --------------------------------------
  // The world point [m] of pixel (row, col) of the scan shown, for a
  // measurement: none outside the scan, where it has no return, or where
  // its geometry found no surface (a mixed pixel at an edge has no normal),
  // and for an unstructured cloud (no range image).
  std::optional<Eigen::Vector3d> world_point(int row, int col) const;
  // Where world point `p` lies in the scan shown, in image coordinates (x =
  // column, y = row, pixel centres at integers; a full circle wraps): none
  // outside its grid, or for a scan without a spherical grid.
  std::optional<Eigen::Vector2d> image_point(const Eigen::Vector3d& p) const;

  // ---- Commands: each one journal entry; false (and status()) when refused
  // Commits the selection of every scan as one object.
  bool commit(const std::string& name, std::optional<std::int64_t> parent);
  bool group(const std::string& name, const std::vector<std::int64_t>& children);
  bool rename(std::int64_t node, const std::string& name);
  bool set_hidden(std::int64_t node, bool hidden);
  bool reparent(std::int64_t node, std::optional<std::int64_t> parent);
  bool remove(std::int64_t node);
  bool separate(std::int64_t node);
  // Automatic proposals for the rest of the shown scan: the group that
  // holds them, none when refused.
  std::optional<std::int64_t> propose();
  // A review of proposals, each one command: rejected ones are deleted
  // (their points back to the pool); accepted ones move to `parent`, one
  // alone renamed to `name`.
  bool reject(const std::vector<std::int64_t>& proposals);
  bool accept(const std::vector<std::int64_t>& proposals, std::optional<std::int64_t> parent,
              const std::string& name);
  // Merges objects into the first (modeling::merge_objects).
  bool merge(const std::vector<std::int64_t>& objects);
  bool recolor(std::int64_t node, const store::ColorEdit& set, bool reset);
  bool clone(std::int64_t source, std::int64_t target);
  // Takes back the newest grow since the last command (the selection is
  // session state), else the newest command. A batch stage (import, geometry,
  // register, merge, harmonize: run from the command line over whole scans)
  // is taken back only with `stages`; without, nothing changes and the stage
  // is returned, for the caller to ask the user first. With `only`, nothing
  // is undone unless the newest command is that one.
  std::optional<store::CommandRecord> undo(bool stages = false,
                                           std::optional<std::int64_t> only = std::nullopt);
  bool redo();

  // The project's measurements (modeling/measurements.hpp), and a new list
  // of them saved as one command; false (and status()) when refused.
  const std::vector<modeling::Measurement>& measurements() const { return measurements_; }
  bool save_measurements(const std::vector<modeling::Measurement>& list, const std::string& what);
  // Writes them as CSV (modeling::measurements_csv) to `file`, whole or not
  // at all; false (and status()) when it cannot.
  bool export_measurements(const std::filesystem::path& file);

  const std::vector<store::ObjectNode>& nodes() const { return nodes_; }
  // Which scans each node's points come from (modeling::scan_coverage),
  // read again after each change of the tree.
  const modeling::ScanCoverage& coverage();
  // What the last action did or why it was refused.
  const std::string& status() const { return status_; }
  // Changes with every change of the project the views show.
  std::int64_t revision() const { return revision_; }

  // The scan's channel with the objects and the selection laid over it,
  // node `highlight` (0: none) standing out.
  render::Picture panorama(render::PanoramaChannel channel, std::int64_t highlight) const;
  // What the 3D view draws: the project's level-of-detail store
  // (docs/lod.md). prepare_views() updates it in place (or builds it anew
  // when it cannot) when a command changed what it reflects (the points
  // and which objects own them); a hide, a
  // recolour or a harmonisation leaves it as it is, and the view shows them
  // from the tree. Empty while there is none.
  const std::filesystem::path& store() const { return store_; }
  // Changes each time the store is updated or built anew: a renderer of
  // another generation draws nodes that changed.
  std::int64_t store_generation() const { return store_generation_; }
  // What this generation changed of the one before: the codes of the nodes
  // the update in place rewrote (render::LodRenderer::follow_update keeps
  // the others); none after a build or a failure, when a renderer must
  // start anew.
  const std::optional<std::vector<std::uint64_t>>& rewritten() const { return rewritten_; }
  // Whether the store reflects the project as it is (reads the store's
  // header and the project's change marks: after a command, not each frame).
  bool store_current() const;
  // Builds what the views show after a change (the store and the nodes'
  // coverage), where it is stale; a background command calls it so that the
  // window's thread does not.
  void prepare_views();
  // Why the 3D view is empty (a scan without geometry); empty when it is not.
  const std::string& view_problem() const { return view_problem_; }
  // How prepare_views() brought the store up to date so far: builds from
  // scratch, and updates in place that rewrote nodes.
  int store_builds() const { return store_builds_; }
  int store_updates() const { return store_updates_; }

 private:
  // Runs a command; a refusal becomes status() and false. After it, the
  // layers and the tree are read again.
  template <typename Action>
  bool act(const std::string& what, Action&& action);
  void reload();
  // The selection of the scan shown, from tools_, as the panorama draws it.
  void show_selection();
  void show_first_scan();
  // After a batch stage was undone or redone: the scan shown again (or the
  // first, when it is gone), with its geometry as it now is.
  void show_first_scan_again();

  store::Project project_;
  bool read_only_ = false;
  std::vector<store::StoredScanSummary> scans_;
  std::int64_t scan_id_ = 0;
  acquisition::Scan scan_;
  std::vector<Eigen::Vector3f> normal_;    // scan frame; zero where none
  std::vector<std::uint32_t> membership_;  // empty: none
  std::vector<std::uint8_t> selection_;    // empty: none
  std::size_t selected_ = 0;
  std::size_t selected_scans_ = 0;
  modeling::SelectionTools tools_;
  std::vector<store::ObjectNode> nodes_;
  std::optional<modeling::ScanCoverage> coverage_;  // none: to be read again
  std::vector<modeling::Measurement> measurements_;
  std::string status_;
  std::int64_t revision_ = 0;
  std::filesystem::path store_;
  std::int64_t store_generation_ = 0;  // stores built or found so far
  std::optional<std::vector<std::uint64_t>> rewritten_;
  std::string view_problem_;
  int store_builds_ = 0, store_updates_ = 0;
  std::int64_t measurements_revision_ = 0;  // the project's revision they were read at
};

}  // namespace scanbench::app::workbench

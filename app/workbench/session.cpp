#include "app/workbench/session.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <variant>

#include "acquisition/formats/output_file.hpp"
#include "core/errors.hpp"
#include "modeling/export_command.hpp"
#include "modeling/lod/update_lod.hpp"
#include "modeling/store/layer_store.hpp"
#include "modeling/store/typed_layers.hpp"

namespace scanbench::app::workbench {

namespace {

// The stages the command line runs over whole scans. The workbench's undo
// stops before them and asks (Session::undo).
bool is_batch_stage(std::string_view name) {
  for (const char* stage : {"import", "geometry", "register", "merge", "harmonize", "migrate"})
    if (name == stage) return true;
  return false;
}

}  // namespace

bool Session::cannot_write(const std::filesystem::path& file) {
  // access() says yes to root whatever the mode, so the mode bits count too:
  // a file nobody may write is opened read-only, root's session included.
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) return false;  // opening it will say what is wrong
  if ((info.st_mode & 0222) == 0 || ::access(file.c_str(), W_OK) != 0) return true;
  const std::filesystem::path folder = file.parent_path().empty() ? "." : file.parent_path();
  return ::access(folder.c_str(), W_OK) != 0;
}

Session::Session(const std::filesystem::path& project, bool read_only)
    : project_(read_only ? store::Project::open_read_only(project) : store::Project::open(project)),
      read_only_(read_only) {
  show_first_scan();
  if (store_current()) {  // drawn at once; else the workbench builds it in the background
    store_ = lod::LodStore::path_for(project_.path());
    store_generation_ = 1;
  }
  if (read_only_)
    status_ =
        "read-only: you can look, grow selections, select nodes and frame them; nothing is "
        "written";
}

void Session::show_first_scan() {
  scans_ = project_.scans();
  if (scans_.empty()) {
    scan_ = {};
    scan_id_ = 0;
    normal_.clear();
    clear_constraints();
    reload();
    return;
  }
  open_scan(scans_.front().id);
}

void Session::open_scan(std::int64_t id) {
  scan_ = project_.load_scan(id);
  scan_id_ = id;
  const std::optional<acquisition::ScanGeometry> geometry = store::load_geometry(project_, id);
  normal_ = geometry ? geometry->normal : std::vector<Eigen::Vector3f>{};
  clear_constraints();
  tools_.open_scan(project_, id);
  reload();
}

std::string Session::missing() const {
  if (scans_.empty())
    return "the project has no scans: import some with `scanbench import`, or redo (Ctrl+Y) an "
           "undone import";
  if (!has_grid())
    return "this scan is an unstructured cloud (imported without a scan grid): it has no range "
           "image to segment; the 3D view shows it";
  if (normal_.empty())
    return "this scan has no geometry: run `scanbench geometry`, or redo (Ctrl+Y) an undone one";
  return "";
}

template <typename Action>
bool Session::act(const std::string& what, Action&& action) {
  if (read_only_) {
    status_ = "refused: the project is open read-only (nothing is written)";
    return false;
  }
  try {
    action();
    status_ = what;
  } catch (const core::InputError& e) {
    status_ = "refused: " + e.problem();
    if (!e.position().detail.empty()) status_ += " (" + e.position().detail + ")";
    return false;
  } catch (const core::RuntimeFailure& e) {
    status_ = "failed: " + e.problem();
    return false;
  }
  tools_.command_ran();
  reload();
  return true;
}

void Session::reload() {
  scans_ = project_.scans();
  if (has_scan() && std::none_of(scans_.begin(), scans_.end(),
                                 [&](const auto& scan) { return scan.id == scan_id_; })) {
    show_first_scan();  // its import was undone, here or by another process
    return;
  }
  nodes_ = project_.object_nodes();
  coverage_.reset();
  try {
    measurements_ = modeling::load_measurements(project_);
    measurements_revision_ = project_.revision();
  } catch (const core::InputError& e) {
    measurements_.clear();
    status_ = "the project's measurements are unreadable: " + e.problem();
  }
  membership_.clear();
  if (has_scan()) {
    membership_ = project_
                      .load_layer<std::uint32_t>(scan_id_, store::layer::kMembership,
                                                 store::ElementType::kU32)
                      .value_or(std::vector<std::uint32_t>{});
  }
  show_selection();
}

void Session::show_selection() {
  selection_.clear();
  const segmentation::PixelSet& selection = tools_.selection(scan_id_);
  if (has_scan() && !selection.empty())
    selection_ = segmentation::to_mask({scan_.rows, scan_.columns, false}, selection);
  selected_ = tools_.selected_pixels();
  selected_scans_ = tools_.selected_scans();
  ++revision_;
}

void Session::select_pixels(const std::map<std::int64_t, std::vector<std::uint32_t>>& region,
                            const std::string& what) {
  std::size_t taken = 0;
  for (const auto& [scan_id, pixels] : region) taken += pixels.size();
  // The selection is session state: selecting writes nothing, read-only too.
  try {
    const std::size_t selected = tools_.select_pixels(project_, region, mode);
    status_ = what + ": " + std::to_string(taken) + " points in " + std::to_string(region.size()) +
              " scan(s); selection " + std::to_string(selected);
  } catch (const core::InputError& e) {
    status_ = "refused: " + e.problem();
  }
  show_selection();
}

void Session::click(double x, double y) {
  if (!has_grid()) {
    status_ = "refused: " + missing();
    return;
  }
  const Eigen::Vector2d xy(x, y);
  const segmentation::GridPixel pixel = segmentation::nearest_pixel(xy);
  if (pixel.row < 0 || pixel.col < 0 || pixel.row >= scan_.rows || pixel.col >= scan_.columns)
    return;
  switch (tool) {
    case Tool::kLasso:
      tools_.add_lasso_vertex(scan_id_, xy);
      status_ = "lasso: " + std::to_string(tools_.lasso().size()) + " vertices (Enter closes it)";
      return;
    case Tool::kBarrier:
      tools_.add_barrier_vertex(scan_id_, xy);
      status_ = "barrier: " + std::to_string(tools_.barriers().back().size()) +
                " vertices (Enter ends it)";
      return;
    case Tool::kBrush:
      status_ = "the brush selects in the 3D view: drag over the surfaces there";
      return;
    case Tool::kSeed:
      break;
  }
  segmentation::GrowSettings grow = segmentation::default_grow_settings(channel);
  grow.tolerance = tolerance;
  // The selection is session state: growing it writes nothing, read-only too.
  try {
    const modeling::SelectResult result =
        tools_.select(project_, tools_.select_at(scan_id_, xy, mode, grow));
    status_ = result.seed_open ? "grew " + std::to_string(result.region_pixels) +
                                     " pixels; selection " + std::to_string(result.selected_pixels)
                               : "the seed cannot grow there: " + result.refused;
  } catch (const core::InputError& e) {
    status_ = "refused: " + e.problem();
    if (!e.position().detail.empty()) status_ += " (" + e.position().detail + ")";
  } catch (const core::RuntimeFailure& e) {
    status_ = "failed: " + e.problem();
  }
  show_selection();
}

void Session::finish_polyline() {
  if (tool == Tool::kLasso) {
    status_ = tools_.close_lasso() ? "lasso closed: grows stay inside it"
                                   : "a lasso needs at least 3 vertices; it has " +
                                         std::to_string(tools_.lasso().size());
  }
  if (tool == Tool::kBarrier) tools_.end_barrier();
}

void Session::clear_constraints() {
  tools_.clear();
}

bool Session::commit(const std::string& name, std::optional<std::int64_t> parent) {
  return act("committed \"" + name + "\"",
             [&] { tools_.commit_all(project_, scan_id_, name, parent); });
}

bool Session::group(const std::string& name, const std::vector<std::int64_t>& children) {
  std::optional<std::int64_t> parent;
  for (const store::ObjectNode& n : nodes_) {
    if (!children.empty() && n.id == children.front()) parent = n.parent;
  }
  return act("grouped " + std::to_string(children.size()) + " node(s) as \"" + name + "\"", [&] {
    modeling::group_nodes(project_, {name, parent, children});
  });
}

bool Session::rename(std::int64_t node, const std::string& name) {
  return act("renamed to \"" + name + "\"", [&] {
    modeling::edit_node(project_, {node, name, std::nullopt, std::nullopt, {}});
  });
}

bool Session::set_hidden(std::int64_t node, bool hidden) {
  return act(hidden ? "hidden" : "shown", [&] {
    modeling::edit_node(project_, {node, std::nullopt, hidden, std::nullopt, {}});
  });
}

bool Session::reparent(std::int64_t node, std::optional<std::int64_t> parent) {
  return act("moved", [&] {
    modeling::edit_node(project_, {node, std::nullopt, std::nullopt, parent, {}});
  });
}

bool Session::remove(std::int64_t node) {
  return act("deleted (its points are to be segmented again)", [&] {
    modeling::delete_node(project_, {node, modeling::DeletedPoints::kToPool, {}});
  });
}

bool Session::reject(const std::vector<std::int64_t>& proposals) {
  if (proposals.empty()) return false;
  modeling::DeleteSettings settings{proposals.front(), modeling::DeletedPoints::kToPool, {}};
  settings.others.assign(proposals.begin() + 1, proposals.end());
  return act("rejected " + std::to_string(proposals.size()) +
                 " proposal(s): their points are to be segmented again",
             [&] { modeling::delete_node(project_, settings); });
}

bool Session::accept(const std::vector<std::int64_t>& proposals, std::optional<std::int64_t> parent,
                     const std::string& name) {
  if (proposals.empty()) return false;
  modeling::NodeEdit edit;
  edit.node = proposals.front();
  edit.parent = parent;
  if (proposals.size() == 1) edit.name = name;
  edit.others.assign(proposals.begin() + 1, proposals.end());
  return act("accepted " + std::to_string(proposals.size()) + " proposal(s)",
             [&] { modeling::edit_node(project_, edit); });
}

bool Session::separate(std::int64_t node) {
  return act("separated into its connected parts", [&] {
    modeling::separate_object(project_, {node, scan_id_});
  });
}

std::optional<std::int64_t> Session::propose() {
  modeling::ProposeSettings settings;
  settings.scan_id = scan_id_;
  modeling::SeparateResult result;
  if (!act("", [&] { result = modeling::propose_objects(project_, settings); }))
    return std::nullopt;
  status_ = std::to_string(result.nodes.size()) +
            " proposals for the rest of the scan: review them in Proposals";
  // The group is the newest node that is not one of them.
  std::optional<std::int64_t> group;
  for (const store::ObjectNode& n : nodes_) {
    if (n.kind == store::NodeKind::kGroup && (!group || n.id > *group)) group = n.id;
  }
  return group;
}

bool Session::keep_selections(bool at_close) {
  if (read_only_) return true;
  modeling::SelectionTools::Kept kept;
  if (!act("", [&] { kept = tools_.keep(project_, at_close); })) return false;
  if (kept.held_back) {
    status_ = "the selection is not kept: keeping it would end the redo chain";
  } else if (kept.command_id != 0) {
    status_ = "kept the selection in the project (command " + std::to_string(kept.command_id) + ")";
  } else {
    status_ = "the project keeps this selection already";
  }
  return true;
}

bool Session::save_measurements(const std::vector<modeling::Measurement>& list,
                                const std::string& what) {
  return act(what,
             [&] { modeling::save_measurements(project_, list, what, measurements_revision_); });
}

bool Session::export_measurements(const std::filesystem::path& file) {
  try {
    // The project and its scans' sources are never replaced; an earlier
    // export is (the field names it).
    const std::filesystem::path outputs[] = {file};
    modeling::refuse_to_replace_inputs(project_, outputs, true);
    acquisition::OutputFile out(file);
    out.write(modeling::measurements_csv(measurements_));
    out.commit();
  } catch (const core::InputError& e) {
    status_ = "refused: " + e.problem();
    return false;
  } catch (const core::RuntimeFailure& e) {
    status_ = "failed: " + e.problem();
    return false;
  }
  status_ = "wrote " + std::to_string(measurements_.size()) + " measurements to " + file.string();
  return true;
}

bool Session::merge(const std::vector<std::int64_t>& objects) {
  return act("merged " + std::to_string(objects.size()) + " objects",
             [&] { modeling::merge_objects(project_, {objects}); });
}

bool Session::recolor(std::int64_t node, const store::ColorEdit& set, bool reset) {
  return act("recoloured", [&] { modeling::recolor_object(project_, {node, set, reset}); });
}

bool Session::clone(std::int64_t source, std::int64_t target) {
  modeling::CloneSettings settings;
  settings.target = target;
  settings.source_node = source;
  return act("cloned the colours", [&] { modeling::clone_color(project_, settings); });
}

std::optional<store::CommandRecord> Session::undo(bool stages, std::optional<std::int64_t> only) {
  if (!only && tools_.undo_selection()) {  // session state: read-only too
    status_ = "took back the last grow";
    show_selection();
    return std::nullopt;
  }
  if (read_only_) {
    status_ = "refused: the project is open read-only (nothing is written)";
    return std::nullopt;
  }
  std::optional<store::CommandRecord> newest;
  for (const store::CommandRecord& record : project_.history()) {
    if (record.state == store::CommandState::kDone) newest = record;
  }
  if (!newest || !newest->undoable) {
    status_ = "nothing to undo";
    return std::nullopt;
  }
  if (only && newest->id != *only) {
    status_ = "nothing undone: another process changed the journal meanwhile";
    return std::nullopt;
  }
  if (is_batch_stage(newest->name) && !stages) {
    status_ = "undo stopped at \"" + newest->name + "\", a batch stage";
    return newest;
  }
  std::optional<store::CommandRecord> undone;
  act("", [&] { undone = project_.undo(newest->id); });
  if (undone) tools_.command_undone(project_, undone->id);
  if (undone && is_batch_stage(undone->name)) show_first_scan_again();
  show_selection();
  if (status_.empty()) status_ = undone ? "undid " + undone->name : "nothing to undo";
  return std::nullopt;
}

bool Session::redo() {
  if (tools_.redo_selection()) {
    status_ = "grew the selection again";
    show_selection();
    return true;
  }
  if (tools_.grown_since_command()) {
    status_ = "nothing to redo: the selection grew since (Ctrl+Z takes the grows back first)";
    return false;
  }
  std::optional<store::CommandRecord> redone;
  act("", [&] { redone = project_.redo(); });
  if (redone) tools_.command_redone(project_, redone->id);
  if (redone && is_batch_stage(redone->name)) show_first_scan_again();
  show_selection();
  if (status_.empty()) status_ = redone ? "redid " + redone->name : "nothing to redo";
  return redone.has_value();
}

void Session::show_first_scan_again() {
  const std::string said = status_;
  scans_ = project_.scans();
  const bool still_there = std::any_of(scans_.begin(), scans_.end(),
                                       [&](const auto& scan) { return scan.id == scan_id_; });
  if (still_there) {
    open_scan(scan_id_);  // its geometry may have come or gone
  } else {
    show_first_scan();
  }
  status_ = said;
}

std::optional<Eigen::Vector3d> Session::world_point(int row, int col) const {
  if (!has_grid()) return std::nullopt;  // a cloud's pixels are not a picture
  if (row < 0 || col < 0 || row >= scan_.rows || col >= scan_.columns) return std::nullopt;
  const std::size_t p = scan_.index(row, col);
  if (scan_.valid[p] == 0) return std::nullopt;
  if (!normal_.empty() && normal_[p].squaredNorm() == 0.0f) return std::nullopt;
  return acquisition::point_in_world(scan_, row, col);
}

std::optional<Eigen::Vector2d> Session::image_point(const Eigen::Vector3d& p) const {
  if (!has_scan() || !scan_.is_spherical()) return std::nullopt;
  const auto& angles = std::get<acquisition::SphericalAngles>(scan_.angles);
  const Eigen::Vector3d q = scan_.T_world_scan.inverse() * p;
  const double horizontal = std::hypot(q.x(), q.y());
  if (horizontal == 0.0 && q.z() == 0.0) return std::nullopt;
  double u = (std::atan2(q.y(), q.x()) - angles.azimuth_start_rad) / angles.azimuth_step_rad;
  const double v =
      (std::atan2(q.z(), horizontal) - angles.elevation_start_rad) / angles.elevation_step_rad;
  if (acquisition::wraps_around(scan_)) {  // into [-½, columns - ½)
    const double period = 2.0 * std::numbers::pi / std::abs(angles.azimuth_step_rad);
    u -= period * std::floor((u + 0.5) / period);
  }
  if (!(u >= -0.5 && u <= scan_.columns - 0.5 && v >= -0.5 && v <= scan_.rows - 0.5))
    return std::nullopt;
  return Eigen::Vector2d(u, v);
}

void Session::prepare_views() {
  if (!store_current()) {
    view_problem_.clear();
    rewritten_.reset();
    try {
      core::Progress quiet;  // the window shows the command running
      const lod::LodRefreshResult refreshed = lod::refresh_lod(project_, {}, quiet);
      // A store found at another path is another store.
      if (refreshed.updated && refreshed.store() == store_)
        rewritten_ = refreshed.updated->rewritten;
      store_ = refreshed.store();
      if (refreshed.built) ++store_builds_;
      if (refreshed.updated &&
          refreshed.updated->nodes_written + refreshed.updated->nodes_removed > 0)
        ++store_updates_;
    } catch (const core::FileError& e) {
      // A scan without geometry, a store that cannot be written: the 3D
      // view says so and stays empty.
      store_.clear();
      const std::string& where = e.position().detail;
      view_problem_ = (where.empty() ? "" : where + " ") + e.problem();
    }
    ++store_generation_;
  }
  if (!nodes_.empty()) coverage();
}

const modeling::ScanCoverage& Session::coverage() {
  if (!coverage_) {
    try {
      coverage_ = modeling::scan_coverage(project_);
    } catch (const core::FileError& e) {  // a damaged layer: the panel shows none
      coverage_ = modeling::ScanCoverage{};
      status_ = "the objects' scans are unreadable: " + std::string(e.what());
    }
  }
  return *coverage_;
}

render::Picture Session::panorama(render::PanoramaChannel channel, std::int64_t highlight) const {
  return render::panorama_picture(
      scan_, {normal_, membership_, selection_, static_cast<std::uint32_t>(highlight)}, channel);
}

bool Session::store_current() const {
  return lod::current_lod_store(project_).has_value();
}

}  // namespace scanbench::app::workbench

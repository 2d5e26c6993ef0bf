#include "app/workbench/session.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "modeling/layers.hpp"
#include "modeling/scan_layers.hpp"

namespace scanbench::app::workbench {

namespace {

// The object-id colours of the renderer's object mode (splat_shaders.cpp).
std::array<std::uint8_t, 3> object_color(std::uint32_t id) {
  const std::uint32_t h = id * 2654435761u;
  const auto c = [](std::uint32_t v) {
    return static_cast<std::uint8_t>(std::lround(255.0 * (0.25 + 0.7 * (v & 255u) / 255.0)));
  };
  return {c(h), c(h >> 8), c(h >> 16)};
}

std::uint8_t blend(std::uint8_t a, std::uint8_t b, float t) {
  return static_cast<std::uint8_t>(
      std::lround((1.0f - t) * static_cast<float>(a) + t * static_cast<float>(b)));
}

}  // namespace

Session::Session(const std::filesystem::path& project)
    : project_(modeling::Project::open(project)) {
  scans_ = project_.scans();
  if (scans_.empty())
    throw core::InputError(project.string(), {}, "the project has no scans: import some first");
  open_scan(scans_.front().id);
}

void Session::open_scan(std::int64_t id) {
  scan_ = project_.load_scan(id);
  scan_id_ = id;
  const std::optional<acquisition::ScanGeometry> geometry = modeling::load_geometry(project_, id);
  normal_ = geometry ? geometry->normal : std::vector<Eigen::Vector3f>{};
  clear_constraints();
  reload();
}

template <typename Action>
bool Session::act(const std::string& what, Action&& action, bool changes_model) {
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
  if (changes_model) ++model_changes_;
  reload();
  return true;
}

void Session::reload() {
  scans_ = project_.scans();
  nodes_ = project_.object_nodes();
  membership_ = project_
                    .load_layer<std::uint32_t>(scan_id_, modeling::layer::kMembership,
                                               modeling::ElementType::kU32)
                    .value_or(std::vector<std::uint32_t>{});
  selection_ = project_
                   .load_layer<std::uint8_t>(scan_id_, modeling::layer::kSelection,
                                             modeling::ElementType::kU8)
                   .value_or(std::vector<std::uint8_t>{});
  selected_ = static_cast<std::size_t>(std::count(selection_.begin(), selection_.end(), 1));
  ++revision_;
}

void Session::click(double x, double y) {
  if (x < 0.0 || y < 0.0 || x >= scan_.columns || y >= scan_.rows) return;
  switch (tool) {
    case Tool::kLasso:
      if (lasso_closed_) {
        lasso_.clear();
        lasso_closed_ = false;
      }
      lasso_.emplace_back(x, y);
      status_ = "lasso: " + std::to_string(lasso_.size()) + " vertices (Enter closes it)";
      return;
    case Tool::kBarrier:
      if (!drawing_barrier_) barriers_.emplace_back();
      drawing_barrier_ = true;
      barriers_.back().emplace_back(x, y);
      status_ = "barrier: " + std::to_string(barriers_.back().size()) + " vertices (Enter ends it)";
      return;
    case Tool::kSeed:
      break;
  }
  modeling::SelectSettings settings;
  settings.scan_id = scan_id_;
  settings.seed_col = static_cast<int>(x);
  settings.seed_row = static_cast<int>(y);
  settings.mode = mode;
  settings.grow = segmentation::default_grow_settings(channel);
  settings.grow.tolerance = tolerance;
  if (lasso_closed_) settings.constraints.lasso = lasso_;
  settings.constraints.barriers = barriers_;
  modeling::SelectResult result;
  act(
      "", [&] { result = modeling::select_region(project_, settings); }, false);
  if (status_.empty()) {
    status_ = result.seed_open
                  ? "grew " + std::to_string(result.region_pixels) + " pixels; selection " +
                        std::to_string(result.selected_pixels)
                  : "the seed cannot grow there (no normal, taken, or outside the lasso)";
  }
}

void Session::finish_polyline() {
  if (tool == Tool::kLasso && lasso_.size() >= 3) {
    lasso_closed_ = true;
    status_ = "lasso closed: grows stay inside it";
  } else if (tool == Tool::kLasso) {
    status_ = "a lasso needs at least 3 vertices; it has " + std::to_string(lasso_.size());
  }
  if (tool == Tool::kBarrier) drawing_barrier_ = false;
}

void Session::clear_constraints() {
  lasso_.clear();
  lasso_closed_ = false;
  barriers_.clear();
  drawing_barrier_ = false;
}

bool Session::commit(const std::string& name, std::optional<std::int64_t> parent) {
  return act("committed \"" + name + "\"", [&] {
    modeling::commit_selection(project_, {scan_id_, name, parent});
  });
}

bool Session::group(const std::string& name, const std::vector<std::int64_t>& children) {
  std::optional<std::int64_t> parent;
  for (const modeling::ObjectNode& n : nodes_) {
    if (!children.empty() && n.id == children.front()) parent = n.parent;
  }
  return act("grouped " + std::to_string(children.size()) + " node(s) as \"" + name + "\"", [&] {
    modeling::group_nodes(project_, {name, parent, children});
  });
}

bool Session::rename(std::int64_t node, const std::string& name) {
  return act("renamed to \"" + name + "\"", [&] {
    modeling::edit_node(project_, {node, name, std::nullopt, std::nullopt});
  });
}

bool Session::set_hidden(std::int64_t node, bool hidden) {
  return act(hidden ? "hidden" : "shown", [&] {
    modeling::edit_node(project_, {node, std::nullopt, hidden, std::nullopt});
  });
}

bool Session::reparent(std::int64_t node, std::optional<std::int64_t> parent) {
  return act("moved", [&] {
    modeling::edit_node(project_, {node, std::nullopt, std::nullopt, parent});
  });
}

bool Session::remove(std::int64_t node) {
  return act("deleted (its points are to be segmented again)", [&] {
    modeling::delete_node(project_, {node, modeling::DeletedPoints::kToPool});
  });
}

bool Session::separate(std::int64_t node) {
  return act("separated into its connected parts", [&] {
    modeling::separate_object(project_, {node, scan_id_});
  });
}

bool Session::propose() {
  modeling::ProposeSettings settings;
  settings.scan_id = scan_id_;
  return act("proposed objects for the rest of the scan",
             [&] { modeling::propose_objects(project_, settings); });
}

bool Session::recolor(std::int64_t node, const modeling::ColorEdit& set, bool reset) {
  return act("recoloured", [&] { modeling::recolor_object(project_, {node, set, reset}); });
}

bool Session::clone(std::int64_t source, std::int64_t target) {
  modeling::CloneSettings settings;
  settings.target = target;
  settings.source_node = source;
  return act("cloned the colours", [&] { modeling::clone_color(project_, settings); });
}

bool Session::undo() {
  std::optional<modeling::CommandRecord> undone;
  act("", [&] { undone = project_.undo(); });
  status_ = undone ? "undid " + undone->name : "nothing to undo";
  return undone.has_value();
}

bool Session::redo() {
  std::optional<modeling::CommandRecord> redone;
  act("", [&] { redone = project_.redo(); });
  status_ = redone ? "redid " + redone->name : "nothing to redo";
  return redone.has_value();
}

Picture Session::panorama(PanoramaChannel which) const {
  Picture out;
  out.width = scan_.columns;
  out.height = scan_.rows;
  const std::size_t n = scan_.pixel_count();
  out.rgba.assign(4 * n, 0);
  float low = 0.0f, high = 1.0f;
  if (which == PanoramaChannel::kRange) {
    std::vector<float> ranges;
    for (std::size_t i = 0; i < n; ++i)
      if (scan_.valid[i]) ranges.push_back(scan_.range_m[i]);
    if (!ranges.empty()) {
      std::sort(ranges.begin(), ranges.end());
      low = ranges[ranges.size() / 50];
      high = std::max(ranges[ranges.size() - 1 - ranges.size() / 50], low + 1e-3f);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* p = &out.rgba[4 * i];
    p[3] = 255;
    if (!scan_.valid[i]) {
      p[0] = p[1] = p[2] = 24;
      continue;
    }
    switch (which) {
      case PanoramaChannel::kColor:
        if (scan_.has_color()) {
          for (int c = 0; c < 3; ++c) p[c] = scan_.rgb[3 * i + static_cast<std::size_t>(c)];
          break;
        }
        [[fallthrough]];
      case PanoramaChannel::kIntensity: {
        const float v = scan_.has_intensity() ? std::clamp(scan_.intensity[i], 0.0f, 1.0f) : 0.5f;
        p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(255.0f * v));
        break;
      }
      case PanoramaChannel::kRange: {
        const float t = std::clamp((scan_.range_m[i] - low) / (high - low), 0.0f, 1.0f);
        p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(255.0f * (1.0f - t)));
        break;
      }
      case PanoramaChannel::kNormal: {
        const Eigen::Vector3f normal = normal_.empty() ? Eigen::Vector3f::Zero() : normal_[i];
        for (int c = 0; c < 3; ++c)
          p[c] = static_cast<std::uint8_t>(std::lround(127.5f + 127.5f * normal[c]));
        break;
      }
    }
    const std::uint32_t owner = membership_.empty() ? 0 : membership_[i];
    if (owner != 0 && owner != modeling::kDeletedPoints) {
      const auto tint = object_color(owner);
      for (int c = 0; c < 3; ++c) p[c] = blend(p[c], tint[static_cast<std::size_t>(c)], 0.45f);
    }
    if (!selection_.empty() && selection_[i] != 0) {
      const std::array<std::uint8_t, 3> yellow = {255, 230, 40};
      for (int c = 0; c < 3; ++c) p[c] = blend(p[c], yellow[static_cast<std::size_t>(c)], 0.6f);
    }
  }
  return out;
}

const modeling::RenderModel& Session::render_model() {
  if (!model_ || model_revision_ != model_changes_) {
    model_ = modeling::build_render_model(project_, {});
    model_revision_ = model_changes_;
  }
  return *model_;
}

}  // namespace scanbench::app::workbench

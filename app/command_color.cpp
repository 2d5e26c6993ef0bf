// scanbench recolor PROJECT --object ID [--brightness B] [--contrast C] [--gamma G] [--hue DEG]
//                           [--saturation S] [--reset] [--json]
// scanbench recolor PROJECT --to ID (--clone SRC_ID | --clone-region SCAN:ROW0:COL0:ROW1:COL1 |
//                           --paint-color '#RRGGBB') [--paint] [--json]
// scanbench harmonize PROJECT [--model gain-offset|matrix] [--settings FILE] [--threads N]
//                             [--memory-limit SIZE] [--json]
#include <fmt/core.h>

#include <charconv>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/progress_bar.hpp"
#include "core/errors.hpp"
#include "modeling/color_commands.hpp"
#include "modeling/harmonize_command.hpp"
#include "modeling/merge_command.hpp"
#include "modeling/register_command.hpp"

namespace scanbench::app {
namespace {

struct RecolorOptions {
  std::string project;
  std::string object;  // an id or a unique name
  store::ColorEdit set;
  bool reset = false;
  std::string target;
  std::string clone;
  std::string clone_region;
  std::string paint_color;
  bool paint = false;
  bool json = false;
};

// A node named by its id or by its name (which must be unique).
std::int64_t node_named(const store::Project& project, const std::string& option,
                        const std::string& text) {
  std::int64_t id = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), id);
  if (error == std::errc() && end == text.data() + text.size()) return id;
  const std::vector<std::int64_t> found = project.nodes_named(text);
  if (found.size() == 1) return found.front();
  core::FilePosition position;
  position.detail = option;
  throw core::InputError(project.path().string(), position,
                         found.empty() ? "no node is named \"" + text + "\""
                                       : "several nodes are named \"" + text + "\": give the id");
}

// "SCAN:ROW0:COL0:ROW1:COL1".
modeling::PixelRect parse_region(const std::string& text) {
  std::int64_t scan = 0;
  std::array<int, 4> v{};
  const char* end = text.data() + text.size();
  const auto bad = [&] {
    return CLI::ValidationError("--clone-region",
                                "expected SCAN:ROW0:COL0:ROW1:COL1 (whole numbers), got " + text);
  };
  std::from_chars_result read = std::from_chars(text.data(), end, scan);
  if (read.ec != std::errc() || read.ptr == end || *read.ptr != ':') throw bad();
  for (std::size_t k = 0; k < v.size(); ++k) {
    // Into int directly: a value out of its range is an error, not a wrap.
    read = std::from_chars(read.ptr + 1, end, v[k]);
    const bool last = k + 1 == v.size();
    if (read.ec != std::errc() || (last ? read.ptr != end : (read.ptr == end || *read.ptr != ':')))
      throw bad();
  }
  return {scan, v[0], v[2], v[1], v[3]};
}

// "#RRGGBB" or "RRGGBB".
std::array<std::uint8_t, 3> parse_color(const std::string& text) {
  const std::string hex = !text.empty() && text[0] == '#' ? text.substr(1) : text;
  unsigned value = 0;
  const auto [next, error] = std::from_chars(hex.data(), hex.data() + hex.size(), value, 16);
  if (hex.size() != 6 || error != std::errc() || next != hex.data() + hex.size())
    throw CLI::ValidationError("--paint-color", "expected #RRGGBB, got " + text);
  return {static_cast<std::uint8_t>(value >> 16), static_cast<std::uint8_t>(value >> 8),
          static_cast<std::uint8_t>(value)};
}

void print_edit(const store::ObjectNode& node) {
  const std::string json = store::to_json(node.color);
  fmt::print("node {} ({}): colour edit {}\n", node.id,
             core::one_line(node.name, core::kMaxMessagePart),
             json.empty() ? "none (inherits its parent's)" : json);
}

void run_recolor(const RecolorOptions& options) {
  const bool editing = !options.object.empty();
  const bool cloning = !options.target.empty();
  if (editing == cloning)
    throw CLI::ValidationError("recolor", "give --object ID (an edit) or --to ID (a clone)");
  const bool sources = !options.clone.empty() || !options.clone_region.empty() ||
                       !options.paint_color.empty() || options.paint;
  if (editing && sources)
    throw CLI::ValidationError("--object", "edits an object; a clone names its target with --to");
  if (cloning && (!options.set.empty() || options.reset))
    throw CLI::ValidationError("--to", "clones colours; edit parameters go with --object");
  store::Project project = store::Project::open(options.project);
  std::int64_t node_id = 0;
  std::string result;
  if (editing) {
    if (options.set.empty() && !options.reset)
      throw CLI::ValidationError("--object",
                                 "give at least one of --brightness, --contrast, "
                                 "--gamma, --hue, --saturation or --reset");
    const modeling::NodeCommandResult out = naming_project(project.path(), [&] {
      return modeling::recolor_object(
          project, {node_named(project, "--object", options.object), options.set, options.reset});
    });
    node_id = out.node_id;
  } else {
    modeling::CloneSettings settings;
    settings.target = node_named(project, "--to", options.target);
    if (!options.clone.empty())
      settings.source_node = node_named(project, "--clone", options.clone);
    if (!options.clone_region.empty()) settings.source_region = parse_region(options.clone_region);
    if (!options.paint_color.empty()) settings.source_color = parse_color(options.paint_color);
    settings.paint = options.paint;
    const modeling::CloneResult out =
        naming_project(project.path(), [&] { return modeling::clone_color(project, settings); });
    node_id = out.node_id;
    if (!options.json) {
      fmt::print("matched {} target points to {} source points\n", out.target_points,
                 out.source_points);
    }
  }
  for (const store::ObjectNode& node : project.object_nodes()) {
    if (node.id != node_id) continue;
    if (options.json) {
      const std::string json = store::to_json(node.color);
      fmt::print("{{\"node\":{},\"color\":{}}}\n", node.id, json.empty() ? "{}" : json);
    } else {
      print_edit(node);
    }
  }
}

struct HarmonizeOptions {
  std::string project;
  modeling::HarmonizeCommandSettings settings;
  std::string settings_file;
  int threads = 0;
  bool json = false;
  std::uint64_t memory_limit = 0;
};

void run_harmonize(const HarmonizeOptions& options) {
  modeling::HarmonizeCommandSettings settings =
      options.settings_file.empty()
          ? options.settings
          : read_settings_file<modeling::HarmonizeCommandSettings>(options.settings_file);
  settings.pairs.threads = settings.solve.threads = options.threads;
  store::Project project = store::Project::open(options.project);
  ProgressBar progress;
  const modeling::HarmonizeCommandResult out = modeling::harmonize_project(
      project, settings, progress, memory_limit_of(options.memory_limit));
  if (options.json) {
    fmt::print("{}\n", modeling::result_json(out));
    return;
  }
  fmt::print("{:>4}  {:<24} {:>9} {:>10} {:>9}  {}\n", "id", "name", "pairs", "ΔE before",
             "ΔE after", "gains (R G B), offsets");
  for (const modeling::HarmonizeCommandScan& s : out.scans) {
    fmt::print("{:>4}  {:<24} {:>9} {:>10.2f} {:>9.2f}  ", s.id, s.name, s.pairs, s.delta_e_before,
               s.delta_e_after);
    if (!s.reference) {
      fmt::print("overlaps no other scan: unchanged\n");
      continue;
    }
    if (*s.reference == s.id) {
      fmt::print("fixed: the others are brought to it\n");
      continue;
    }
    fmt::print("{:.3f} {:.3f} {:.3f}, {:+.4f} {:+.4f} {:+.4f}\n", s.correction.matrix(0, 0),
               s.correction.matrix(1, 1), s.correction.matrix(2, 2), s.correction.offset.x(),
               s.correction.offset.y(), s.correction.offset.z());
  }
  fmt::print(
      "{} colour pairs: mean ΔE {:.2f} → {:.2f} ({} iterations, {:.2f} s); corrections "
      "stored in {}\n",
      out.pairs, out.delta_e_before, out.delta_e_after, out.iterations, out.seconds,
      options.project);
}

}  // namespace

void add_recolor_command(CLI::App& app) {
  auto options = std::make_shared<RecolorOptions>();
  CLI::App* command = app.add_subcommand(
      "recolor",
      "Edit an object's colours without changing the scans (one command, undoable): set its "
      "brightness, contrast, gamma, hue or saturation (in CIE L*a*b*; parameters it does not set "
      "it inherits from its group), or make its colours match another object, a region of a "
      "scan, or one colour.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--object", options->object, "The node to edit (id or unique name)");
  command->add_option("--brightness", options->set.brightness, "Added to L* (-100…100)");
  command->add_option("--contrast", options->set.contrast, "L* scaled about 50 (1: none)");
  command->add_option("--gamma", options->set.gamma, "L*/100 raised to 1/gamma (1: none)");
  command->add_option("--hue", options->set.hue_deg, "a*b* rotated by this many degrees");
  command->add_option("--saturation", options->set.saturation, "Chroma × this (1: none)");
  command->add_flag("--reset", options->reset,
                    "Drop the node's own parameters first (it inherits them again)");
  command->add_option("--to", options->target,
                      "The node whose colours a clone changes (id or unique name)");
  command->add_option("--clone", options->clone,
                      "Clone from this node's colours as shown (id or unique name)");
  command->add_option("--clone-region", options->clone_region,
                      "Clone from a region of a scan: SCAN:ROW0:COL0:ROW1:COL1 (ends excluded)");
  command->add_option("--paint-color", options->paint_color,
                      "Paint this colour (#RRGGBB), keeping the target's lightness detail");
  command->add_flag("--paint", options->paint,
                    "Paint the source's mean colour instead of matching its spread");
  command->add_flag("--json", options->json, "Print the node's colour edit as JSON");
  command->callback([options] { run_recolor(*options); });
}

void add_harmonize_command(CLI::App& app) {
  auto options = std::make_shared<HarmonizeOptions>();
  CLI::App* command = app.add_subcommand(
      "harmonize",
      "Make the same surface look the same from every scan: corresponding points in the "
      "overlaps of the registered scans give colour pairs, and a robust least-squares solve "
      "gives each scan a colour correction in linear RGB, the first scan fixed. Stored as one "
      "command, undoable; the scans' colours are never changed.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  CLI::Option* settings = add_settings_option(command, options->settings_file);
  command
      ->add_option("--model", options->settings.solve.model,
                   "gain-offset (per channel) or matrix (3 × 3 and offset)")
      ->transform(one_of(std::map<std::string, registration::ColorModel>{
          {"gain-offset", registration::ColorModel::kGainOffset},
          {"matrix", registration::ColorModel::kMatrix}}))
      ->default_str("gain-offset")
      ->excludes(settings);
  add_threads_option(command, options->threads);
  add_memory_limit_option(command, options->memory_limit);
  command->add_flag("--json", options->json, "Print one JSON object");
  command->callback([options] { run_harmonize(*options); });
}

}  // namespace scanbench::app

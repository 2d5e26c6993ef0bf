// scanbench objects PROJECT [--json]
#include <fmt/core.h>

#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "modeling/store/project.hpp"
#include "modeling/tree_commands.hpp"

namespace scanbench::app {
namespace {

struct ObjectsOptions {
  std::string project;
  bool json = false;
};

// The scans a node's points come from, by id: "1 2 4".
std::string scan_list(const modeling::ScanCoverage& coverage, std::int64_t node) {
  std::string out;
  const auto found = coverage.find(node);
  if (found == coverage.end()) return "-";
  for (const auto& [scan, points] : found->second)
    out += (out.empty() ? "" : " ") + std::to_string(scan);
  return out;
}

nlohmann::json to_json(const store::ObjectNode& node, const modeling::ScanCoverage& coverage) {
  nlohmann::json bbox = nullptr;
  if (node.bbox_world) {
    const Eigen::Vector3d lo = node.bbox_world->min(), hi = node.bbox_world->max();
    bbox = {{lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}};
  }
  nlohmann::json out = {
      {"id", node.id},
      {"name", node.name},
      {"kind", node.kind == store::NodeKind::kGroup ? "group" : "object"},
      {"parent", node.parent ? nlohmann::json(*node.parent) : nlohmann::json(nullptr)},
      {"hidden", node.hidden},
      {"points", node.points},
      {"mean_footprint_m",
       node.mean_footprint_m ? nlohmann::json(*node.mean_footprint_m) : nlohmann::json()},
      {"bbox_world", bbox}};
  nlohmann::json scans = nlohmann::json::array();
  if (const auto found = coverage.find(node.id); found != coverage.end()) {
    for (const auto& [scan, points] : found->second)
      scans.push_back({{"scan", scan}, {"points", points}});
  }
  out["scans"] = scans;
  // The node's own colour edit (what it inherits is not repeated).
  if (const std::string color = store::to_json(node.color); !color.empty())
    out["color"] = nlohmann::json::parse(color);
  return out;
}

// The tree depth first, children by id, each level indented by two spaces.
// A node whose parent is not in the tree is printed as a root.
void print_tree(const std::vector<store::ObjectNode>& nodes,
                const modeling::ScanCoverage& coverage) {
  std::map<std::int64_t, const store::ObjectNode*> by_id;
  for (const store::ObjectNode& node : nodes) by_id[node.id] = &node;
  std::map<std::int64_t, std::vector<const store::ObjectNode*>> children;
  std::vector<const store::ObjectNode*> roots;
  for (const store::ObjectNode& node : nodes) {
    if (node.parent && by_id.count(*node.parent)) {
      children[*node.parent].push_back(&node);
    } else {
      roots.push_back(&node);
    }
  }
  fmt::print("{:>5}  {:<7} {:>10}  {:<9}  {}\n", "id", "kind", "points", "scans", "name");
  const std::function<void(const store::ObjectNode&, int)> print = [&](const auto& node,
                                                                       int depth) {
    fmt::print("{:>5}  {:<7} {:>10}  {:<9}  {}{}{}{}\n", node.id,
               node.kind == store::NodeKind::kGroup ? "group" : "object", node.points,
               scan_list(coverage, node.id), std::string(static_cast<std::size_t>(2 * depth), ' '),
               core::one_line(node.name, core::kMaxMessagePart), node.hidden ? " (hidden)" : "",
               node.color.empty() ? "" : " (recoloured)");
    for (const store::ObjectNode* child : children[node.id]) print(*child, depth + 1);
  };
  for (const store::ObjectNode* root : roots) print(*root, 0);
}

void run_objects(const ObjectsOptions& options) {
  const store::Project project = store::Project::open_for_reading(options.project);
  const std::vector<store::ObjectNode> nodes = project.object_nodes();
  const modeling::ScanCoverage coverage = modeling::scan_coverage(project);
  if (!options.json) {
    if (nodes.empty()) {
      fmt::print("{}: no objects yet\n", options.project);
      return;
    }
    print_tree(nodes, coverage);
    return;
  }
  nlohmann::json out = nlohmann::json::array();
  for (const store::ObjectNode& node : nodes) out.push_back(to_json(node, coverage));
  fmt::print("{}\n", nlohmann::json{{"nodes", out}}.dump(2, ' ', false,
                                                         nlohmann::json::error_handler_t::replace));
}

}  // namespace

void add_objects_command(CLI::App& app) {
  auto options = std::make_shared<ObjectsOptions>();
  CLI::App* command = app.add_subcommand(
      "objects", "Print the project's object tree (site, buildings, walls, …) as a tree or JSON.");
  command->add_option("project", options->project, "Project file (.sbproj)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_flag("--json", options->json,
                    "Print {\"nodes\": [{id, name, kind, parent, hidden, points, "
                    "mean_footprint_m, bbox_world, scans: [{scan, points}]}]}");
  command->callback([options] { run_objects(*options); });
}

}  // namespace scanbench::app

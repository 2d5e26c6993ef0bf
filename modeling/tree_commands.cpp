#include "modeling/tree_commands.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <unordered_set>

#include "modeling/node_tree.hpp"

namespace scanbench::modeling {

NodeCommandResult group_nodes(store::Project& project, const GroupSettings& settings) {
  const std::int64_t revision = project.revision();
  require_name(settings.name);
  Tree tree = load_tree(project);
  require_group(tree, settings.parent);
  store::ObjectNode group;
  group.id = fresh_ids(project, 1);
  group.name = settings.name;
  group.kind = store::NodeKind::kGroup;
  group.parent = settings.parent;
  for (const std::int64_t child : settings.children) {
    require_node(tree, child);
    if (settings.parent && is_at_or_above(tree, child, *settings.parent)) {
      refuse("node " + std::to_string(child), "cannot go into a group below itself");
    }
  }
  tree.emplace(group.id, group);
  for (const std::int64_t child : settings.children) tree.at(child).parent = group.id;
  const auto figures = compute_figures(project, tree, {});
  store::Project::Edit edit = project.begin_command("group",
                                                    dump({{"name", settings.name},
                                                          {"parent", parent_json(settings.parent)},
                                                          {"children", settings.children}}),
                                                    revision);
  project.put_node(edit, group);
  for (const std::int64_t child : settings.children) project.put_node(edit, tree.at(child));
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", group.id}}));
  return {command_id, group.id};
}

NodeCommandResult edit_node(store::Project& project, const NodeEdit& change) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  std::vector<std::int64_t> ids = {change.node};
  ids.insert(ids.end(), change.others.begin(), change.others.end());
  nlohmann::json settings = {{"node", change.node}};
  if (!change.others.empty()) settings["others"] = change.others;
  if (change.name) {
    require_name(*change.name);
    settings["name"] = *change.name;
  }
  if (change.hidden) settings["hidden"] = *change.hidden;
  if (change.parent) {
    require_group(tree, *change.parent);
    settings["parent"] = parent_json(*change.parent);
  }
  std::vector<store::ObjectNode> edited;
  for (const std::int64_t id : ids) {
    store::ObjectNode node = require_node(tree, id);
    if (change.name && id == change.node) node.name = *change.name;
    if (change.hidden) node.hidden = *change.hidden;
    if (change.parent) {
      if (*change.parent && is_at_or_above(tree, id, **change.parent))
        refuse("node " + std::to_string(id), "cannot go into a group below itself");
      node.parent = *change.parent;
    }
    tree[node.id] = node;
    edited.push_back(node);
  }
  const auto figures =
      change.parent ? compute_figures(project, tree, {}) : std::map<std::int64_t, Figures>{};
  store::Project::Edit edit = project.begin_command("edit", dump(settings), revision);
  for (const store::ObjectNode& node : edited) project.put_node(edit, node);
  if (change.parent) refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", change.node}}));
  return {command_id, change.node};
}

UngroupResult ungroup_node(store::Project& project, std::int64_t group) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  const store::ObjectNode dissolved = require_node(tree, group);
  if (dissolved.kind != store::NodeKind::kGroup) {
    refuse("node " + std::to_string(group),
           "is an object, not a group: there is nothing to ungroup");
  }
  UngroupResult result;
  for (auto& [id, node] : tree) {
    if (node.parent != group) continue;
    node.parent = dissolved.parent;
    result.children.push_back(id);
  }
  // The ancestors keep the same descendants' points: no figure changes.
  store::Project::Edit edit = project.begin_command("ungroup", dump({{"node", group}}), revision);
  for (const std::int64_t child : result.children) project.put_node(edit, tree.at(child));
  project.remove_node(edit, group);
  result.command_id = edit.command_id();
  edit.commit(dump({{"node", group}, {"children", result.children}}));
  return result;
}

NodeCommandResult merge_objects(store::Project& project, const MergeSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  if (settings.objects.size() < 2) refuse("merge", "needs two objects or more");
  std::unordered_set<std::uint32_t> absorbed;
  for (const std::int64_t id : settings.objects) {
    if (require_node(tree, id).kind != store::NodeKind::kObject) {
      refuse("node " + std::to_string(id), "is a group: only objects can be merged");
    }
    if (id != settings.objects.front() && !absorbed.insert(static_cast<std::uint32_t>(id)).second) {
      refuse("node " + std::to_string(id), "is named twice");
    }
  }
  const auto into = static_cast<std::uint32_t>(settings.objects.front());
  if (absorbed.count(into)) refuse("node " + std::to_string(into), "cannot merge into itself");
  const std::map<std::int64_t, std::vector<std::uint32_t>> changed =
      reassign_pixels(project, absorbed, into);
  for (const std::uint32_t id : absorbed) tree.erase(id);
  const auto figures = compute_figures(project, tree, changed);
  store::Project::Edit edit =
      project.begin_command("merge_objects", dump({{"objects", settings.objects}}), revision);
  for (const std::uint32_t id : absorbed) project.remove_node(edit, id);
  for (const auto& [scan_id, membership] : changed)
    put_membership(project, edit, scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"node", into}, {"merged", settings.objects.size() - 1}}));
  return {command_id, into};
}

NodeCommandResult delete_node(store::Project& project, const DeleteSettings& settings) {
  const std::int64_t revision = project.revision();
  Tree tree = load_tree(project);
  std::vector<std::int64_t> roots = {settings.node};
  roots.insert(roots.end(), settings.others.begin(), settings.others.end());
  for (const std::int64_t root : roots) require_node(tree, root);
  std::vector<std::int64_t> gone;
  for (const auto& entry : tree) {
    const std::int64_t id = entry.first;  // a plain variable: clang 14 captures no bindings
    if (std::any_of(roots.begin(), roots.end(),
                    [&](std::int64_t root) { return is_at_or_above(tree, root, id); }))
      gone.push_back(id);
  }
  const std::uint32_t replacement =
      settings.points == DeletedPoints::kToPool ? 0 : store::kDeletedPoints;
  const std::unordered_set<std::uint32_t> gone_ids(gone.begin(), gone.end());
  const std::map<std::int64_t, std::vector<std::uint32_t>> changed =
      reassign_pixels(project, gone_ids, replacement);
  for (const std::int64_t id : gone) tree.erase(id);
  const auto figures = compute_figures(project, tree, changed);
  nlohmann::json journaled = {
      {"node", settings.node},
      {"points", settings.points == DeletedPoints::kToPool ? "pool" : "deleted"}};
  if (!settings.others.empty()) journaled["others"] = settings.others;
  store::Project::Edit edit = project.begin_command("delete", dump(journaled), revision);
  for (const std::int64_t id : gone) project.remove_node(edit, id);
  for (const auto& [scan_id, membership] : changed)
    put_membership(project, edit, scan_id, membership);
  refresh_figures(project, edit, tree, figures);
  const std::int64_t command_id = edit.command_id();
  edit.commit(dump({{"nodes", gone}}));
  return {command_id, settings.node};
}

ScanCoverage scan_coverage(const store::Project& project) {
  const Tree tree = load_tree(project);
  ScanCoverage coverage;
  for (const store::StoredScanSummary& stored : project.scans()) {
    const auto membership = project.load_layer<std::uint32_t>(stored.id, store::layer::kMembership,
                                                              store::ElementType::kU32);
    if (!membership) continue;
    std::map<std::uint32_t, std::int64_t> owned;
    for (const std::uint32_t owner : *membership) {
      if (owner != 0 && owner != store::kDeletedPoints) ++owned[owner];
    }
    for (const auto& [owner, points] : owned) {
      // The object and each group above it.
      for (auto node = tree.find(owner); node != tree.end();
           node = node->second.parent ? tree.find(*node->second.parent) : tree.end())
        coverage[node->first][stored.id] += points;
    }
  }
  return coverage;
}

}  // namespace scanbench::modeling

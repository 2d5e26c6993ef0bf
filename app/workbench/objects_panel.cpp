#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

using Children = std::map<std::int64_t, std::vector<const store::ObjectNode*>>;

std::string node_label(const store::ObjectNode& node) {
  std::string label = node.name;
  if (node.hidden) label += " (hidden)";
  if (!node.color.empty()) label += " (recoloured)";
  label += "##" + std::to_string(node.id);
  return label;
}

// A node dragged onto `onto` (a group; none: the roots) moves there once
// the tree is drawn.
void accept_drop(WorkbenchState& s, std::optional<std::int64_t> onto) {
  if (const ImGuiPayload* payload = ImGui::AcceptDragDropPayload("scanbench-node")) {
    std::int64_t moved = 0;
    std::memcpy(&moved, payload->Data, sizeof moved);
    if (moved != onto) s.pending_reparent = {moved, onto};
  }
}

void node_tree(WorkbenchState& s, const store::ObjectNode& n, const Children& children) {
  ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_DefaultOpen |
                             ImGuiTreeNodeFlags_SpanAvailWidth;
  if (s.selected.count(n.id)) flags |= ImGuiTreeNodeFlags_Selected;
  const auto found = children.find(n.id);
  if (found == children.end()) flags |= ImGuiTreeNodeFlags_Leaf;
  const bool open = ImGui::TreeNodeEx(node_label(n).c_str(), flags);
  s.probe("node " + n.name);
  if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) {
    if (ImGui::GetIO().KeyCtrl) {
      if (!s.selected.erase(n.id)) s.selected.insert(n.id);
      s.primary_id = n.id;
      s.load_color_editor();
    } else {
      s.select_only(n.id);
    }
  }
  if (ImGui::BeginDragDropSource()) {
    ImGui::SetDragDropPayload("scanbench-node", &n.id, sizeof n.id);
    ImGui::Text("move %s", n.name.c_str());
    ImGui::EndDragDropSource();
  }
  if (n.kind == store::NodeKind::kGroup && ImGui::BeginDragDropTarget()) {
    accept_drop(s, n.id);
    ImGui::EndDragDropTarget();
  }
  if (!open) return;
  if (found != children.end()) {
    for (const store::ObjectNode* child : found->second) node_tree(s, *child, children);
  }
  ImGui::TreePop();
}

// The tree of nodes, roots first; a drop outside every group moves the
// node to the roots.
void tree(WorkbenchState& s) {
  Children children;
  std::vector<const store::ObjectNode*> roots;
  std::set<std::int64_t> ids;
  for (const store::ObjectNode& n : s.session.nodes()) ids.insert(n.id);
  for (const store::ObjectNode& n : s.session.nodes()) {
    if (n.parent && ids.count(*n.parent)) {
      children[*n.parent].push_back(&n);
    } else {
      roots.push_back(&n);
    }
  }
  ImGui::BeginChild("tree", ImVec2(0, s.px(150)), true);
  if (roots.empty()) ImGui::TextDisabled("no objects yet: click a seed, then Commit");
  for (const store::ObjectNode* root : roots) node_tree(s, *root, children);
  ImGui::EndChild();
  if (ImGui::BeginDragDropTarget()) {
    accept_drop(s, std::nullopt);
    ImGui::EndDragDropTarget();
  }
  if (s.pending_reparent) {
    if (s.run("Moving",
              [&s, move = *s.pending_reparent] { s.session.reparent(move.first, move.second); }))
      s.pending_reparent.reset();
  }
}

// The scans the selected node's points come from, with their counts: an
// object drawn in one scan covers the others that sampled its surface. One
// line always, so that the panels below stay where they are.
void coverage_line(WorkbenchState& s, const std::optional<store::ObjectNode>& node) {
  if (!node) {
    ImGui::TextDisabled("select a node to see the scans it covers");
    return;
  }
  const modeling::ScanCoverage& coverage = s.session.coverage();
  const auto found = coverage.find(node->id);
  if (found == coverage.end()) {
    ImGui::TextDisabled("%s: no points", node->name.c_str());
    return;
  }
  std::string text = "in scan";
  const char* separator = " ";
  for (const auto& [scan, points] : found->second) {
    text += separator + std::to_string(scan) + " (" + std::to_string(points) + ")";
    separator = ", ";
  }
  ImGui::TextUnformatted(text.c_str());
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("%s: points in each scan that sampled it", node->name.c_str());
}

}  // namespace

void objects_panel(WorkbenchState& s) {
  if (!ImGui::CollapsingHeader("Objects", ImGuiTreeNodeFlags_DefaultOpen)) return;
  tree(s);
  const auto p = s.primary();
  ImGui::BeginDisabled(s.selected.empty());
  if (ImGui::Button("Group")) s.group();
  s.probe("group");
  ImGui::SameLine();
  if (ImGui::Button("Rename") && p)
    s.run("Renaming", [&s, id = *p, name = s.name_text()] { s.session.rename(id, name); });
  s.probe("rename");
  ImGui::SameLine();
  const std::optional<store::ObjectNode> n = p ? s.node(*p) : std::nullopt;
  if (ImGui::Button(n && n->hidden ? "Show" : "Hide") && n) {
    s.run(n->hidden ? "Showing" : "Hiding",
          [&s, id = n->id, hide = !n->hidden] { s.session.set_hidden(id, hide); });
  }
  s.probe("hide");
  ImGui::SameLine();
  if (ImGui::Button("Delete")) s.remove_selected();
  s.probe("delete");
  ImGui::SameLine();
  if (ImGui::Button("Separate") && p)
    s.run("Separating", [&s, id = *p] { s.session.separate(id); });
  s.probe("separate");
  ImGui::SameLine();
  if (ImGui::Button("Frame")) s.frame_selection();
  s.probe("frame");
  ImGui::EndDisabled();
  coverage_line(s, n);
}

}  // namespace scanbench::app::workbench

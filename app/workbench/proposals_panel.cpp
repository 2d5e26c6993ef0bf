#include <string>
#include <vector>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

namespace {

std::vector<store::ObjectNode> proposals_of(const WorkbenchState& s, std::int64_t group) {
  std::vector<store::ObjectNode> out;
  for (const store::ObjectNode& n : s.session.nodes()) {
    if (n.parent == group) out.push_back(n);
  }
  return out;
}

// The proposals selected in the list, in the list's order.
std::vector<std::int64_t> picked(const WorkbenchState& s,
                                 const std::vector<store::ObjectNode>& proposals) {
  std::vector<std::int64_t> out;
  for (const store::ObjectNode& n : proposals) {
    if (s.selected.count(n.id)) out.push_back(n.id);
  }
  return out;
}

// What the buttons do to the proposals picked.
void act_on(WorkbenchState& s, const std::vector<store::ObjectNode>& proposals,
            std::optional<std::int64_t> group_parent) {
  const std::vector<std::int64_t> ids = picked(s, proposals);
  ImGui::BeginDisabled(ids.empty() || s.session.read_only());
  // Reject and Merge first: their places do not move with Accept's label.
  if (ImGui::Button("Reject") && !ids.empty()) {
    s.run("Rejecting", [&s, ids] {
      s.session.reject(ids);  // one command, one undo
      s.selected.clear();
      s.after_command();
    });
  }
  s.probe("reject proposal");
  ImGui::SameLine();
  ImGui::BeginDisabled(ids.size() < 2);
  if (ImGui::Button("Merge") && ids.size() >= 2) {
    s.run("Merging", [&s, ids] {
      s.session.merge(ids);
      s.select_only(ids.front());
    });
  }
  s.probe("merge proposals");
  ImGui::EndDisabled();
  ImGui::SameLine();
  // Out of review, beside the proposals' group; one alone takes the name
  // field's name.
  const std::string accept =
      ids.size() == 1 ? "Accept as \"" + s.name_text() + "\"###accept" : "Accept###accept";
  if (ImGui::Button(accept.c_str()) && !ids.empty()) {
    s.run("Accepting", [&s, ids, group_parent, name = s.name_text()] {
      s.session.accept(ids, group_parent, name);  // one command, one undo
      s.after_command();
    });
  }
  s.probe("accept proposal");
  ImGui::EndDisabled();
}

}  // namespace

void proposals_panel(WorkbenchState& s) {
  if (s.review_group && !s.node(*s.review_group)) s.review_group.reset();  // undone, or deleted
  if (!s.review_group) return;
  const std::int64_t group = *s.review_group;
  const std::vector<store::ObjectNode> proposals = proposals_of(s, group);
  const std::string title = "Proposals (" + std::to_string(proposals.size()) + " to review)";
  if (!ImGui::CollapsingHeader((title + "###proposals").c_str(), ImGuiTreeNodeFlags_DefaultOpen))
    return;
  ImGui::TextWrapped(
      "Click one to see it (cyan in the panorama, framed in 3D); Ctrl+click "
      "picks more, to merge.");
  ImGui::BeginChild("proposal list", ImVec2(0, s.px(110)), true);
  for (const store::ObjectNode& n : proposals) {
    const std::string label =
        n.name + " (" + std::to_string(n.points) + " points)##p" + std::to_string(n.id);
    ImGui::Selectable(label.c_str(), s.selected.count(n.id) != 0);
    // On the press, as the tree does: Ctrl is read while it is held.
    if (ImGui::IsItemClicked()) {
      if (ImGui::GetIO().KeyCtrl) {
        if (!s.selected.erase(n.id)) s.selected.insert(n.id);
        s.primary_id = n.id;
      } else {
        s.select_only(n.id);
        s.frame_selection();
      }
    }
    s.probe("proposal " + n.name);
  }
  ImGui::EndChild();
  const std::optional<store::ObjectNode> g = s.node(group);
  act_on(s, proposals, g ? g->parent : std::nullopt);
  ImGui::SameLine();
  if (ImGui::Button("Done")) {
    // What is left stays in the group, as objects of the tree.
    s.run("Closing the review", [&s, group, empty = proposals.empty()] {
      if (empty) s.session.remove(group);
      s.review_group.reset();
      s.after_command();
    });
  }
  s.probe("proposals done");
}

}  // namespace scanbench::app::workbench

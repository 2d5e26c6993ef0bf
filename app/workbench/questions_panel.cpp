#include <utility>

#include "app/workbench/panels.hpp"

namespace scanbench::app::workbench {

void questions_panel(WorkbenchState& s) {
  if (!s.question) return;
  const std::string title = s.question->title;
  if (!ImGui::IsPopupOpen(title.c_str())) ImGui::OpenPopup(title.c_str());
  const ImVec2 size = ImGui::GetIO().DisplaySize;
  ImGui::SetNextWindowPos(ImVec2(0.5f * size.x, 0.4f * size.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(s.px(520), 0));
  if (!ImGui::BeginPopupModal(title.c_str(), nullptr, ImGuiWindowFlags_NoResize)) return;
  ImGui::TextWrapped("%s", s.question->text.c_str());
  ImGui::Spacing();
  // The answer runs after the popup closes: it may ask another question.
  std::function<void()> answer;
  std::string label;
  bool answered = false;
  if (ImGui::Button(s.question->yes.c_str())) {
    answer = s.question->on_yes;
    label = s.question->yes;
    answered = true;
  }
  s.probe("question yes");
  ImGui::SameLine();
  if (ImGui::Button("Cancel")) answered = true;
  s.probe("question no");
  // An answer runs as a command; while another is asked for, the question
  // stays.
  if (answered && answer && !s.run(label, std::move(answer))) answered = false;
  if (answered) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
  if (answered) s.question.reset();
}

}  // namespace scanbench::app::workbench

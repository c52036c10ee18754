#include "editor/gui/widget_log.h"

#include <imgui.h>
#include <imgui_internal.h>  // GetItemID: public only from Dear ImGui 1.88

namespace sinew::editor::gui {

void log_last_item(WidgetLog* log, const char* label, WidgetKind kind, bool pressed) {
  if (log == nullptr) return;
  const ImVec2 min = ImGui::GetItemRectMin();
  const ImVec2 max = ImGui::GetItemRectMax();
  // A widget of several parts (DragFloat3, ColorEdit3, InputInt) ends with
  // a group, which has no ID of its own: its parts live under the ID its
  // label pushed, which is the one two such widgets would share.
  ImGuiID id = ImGui::GetItemID();
  if (id == 0) id = ImGui::GetID(label);
  log->push_back(PanelWidget{label, id, kind, min.x, min.y, max.x, max.y, pressed});
}

}  // namespace sinew::editor::gui

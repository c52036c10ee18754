#include "editor/gui/widget_log.h"

#include <imgui.h>
#include <imgui_internal.h>  // GetItemID: public only from Dear ImGui 1.88

namespace sinew::editor::gui {

void log_last_item(WidgetLog* log, const char* label, WidgetKind kind, bool pressed) {
  if (log == nullptr) return;
  const ImVec2 min = ImGui::GetItemRectMin();
  const ImVec2 max = ImGui::GetItemRectMax();
  log->push_back(PanelWidget{label, ImGui::GetItemID(), kind, min.x, min.y, max.x, max.y, pressed});
}

}  // namespace sinew::editor::gui

// WidgetLog: the panel widgets one frame drew, each with its label, its
// Dear ImGui ID and its rectangle in window pixels (top-left origin, the
// coordinates the window's cursor reports). The panels fill it when
// PanelContext::widgets is set, so a test can find a widget, move the
// real pointer onto it and click, and check that no two widgets share an
// ID (two widgets with one ID steal each other's clicks).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sinew::editor::gui {

enum class WidgetKind : std::uint8_t { kHeader, kButton, kField };

struct PanelWidget {
  std::string label;  // as passed to ImGui, "##" suffix included
  std::uint32_t id = 0;
  WidgetKind kind = WidgetKind::kField;
  float min_x = 0.0f, min_y = 0.0f, max_x = 0.0f, max_y = 0.0f;
  bool pressed = false;  // the widget reported a click (buttons) or a toggle (headers) this frame
};

using WidgetLog = std::vector<PanelWidget>;

// Appends the item ImGui submitted last. Does nothing when `log` is null.
void log_last_item(WidgetLog* log, const char* label, WidgetKind kind, bool pressed);

}  // namespace sinew::editor::gui

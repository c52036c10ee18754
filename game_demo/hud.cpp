#include "game_demo/hud.h"

#include <imgui.h>

namespace sinew::demo {

void FrameRateMeter::add_frame(double milliseconds) {
  // About a half-second memory at 60 fps; the first frame seeds it.
  constexpr double kWeight = 0.05;
  smoothed_ms_ = smoothed_ms_ == 0.0 ? milliseconds : smoothed_ms_ + kWeight * (milliseconds - smoothed_ms_);
}

bool draw_hud(const HudFrame& frame, const BakeInfo& bake, HudControls& controls) {
  ImGui::SetNextWindowPos(ImVec2(8.0f, 8.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.75f);
  bool changed = false;
  if (ImGui::Begin("Sinew (F1 hides)", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::Text("%.1f fps   %dx%d", frame.fps, frame.width, frame.height);
    const double mrays = frame.trace_ms > 0.0 ? static_cast<double>(frame.rays) / (frame.trace_ms * 1e3) : 0.0;
    ImGui::Text("%.2f M rays/s traced (%.2f M rays)", mrays, static_cast<double>(frame.rays) * 1e-6);
    ImGui::Text("characters %d (you: %d)", frame.characters, frame.player + 1);
    ImGui::Text("per character: update %.3f ms, trace %.3f ms", frame.per_character.update_ms,
                frame.per_character.trace_ms);
    ImGui::Text("escaped triangles %zu, fallback %.2f ms", frame.escaped_triangles, frame.fallback_ms);
    if (frame.escaped_triangles > 0) {
      // Poses outside the baked pose space: exact, through the fallback, at
      // its cost (docs/EDITOR.md, "Why is my character slow?").
      ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "poses outside the bake: bake what you play");
    }
    if (ImGui::CollapsingHeader("phases (ms, last frame)", ImGuiTreeNodeFlags_DefaultOpen)) {
      double total = 0.0;
      for (const auto& [name, ms] : frame.phases_ms) {
        ImGui::Text("%-14s %7.2f", name.c_str(), ms);
        total += ms;
      }
      ImGui::Text("%-14s %7.2f", "total", total);
    }
    if (ImGui::CollapsingHeader("pose space", ImGuiTreeNodeFlags_DefaultOpen)) {
      ImGui::Text("%s", bake.model.c_str());
      ImGui::Text("%zu triangles, %zu bones", bake.triangles, bake.bones);
      if (bake.from_pack) {
        ImGui::Text("%u pose samples, from the pack (loaded in %.0f ms)", bake.pose_samples, bake.bake_ms);
      } else {
        ImGui::Text("%u pose samples (all clips), baked in %.0f ms", bake.pose_samples, bake.bake_ms);
      }
      ImGui::Text("fuzzy area %.2fx the rest pose's", bake.fuzzy_area_ratio);
    }
    if (ImGui::CollapsingHeader("settings", ImGuiTreeNodeFlags_DefaultOpen)) {
      changed |= ImGui::SliderInt("threads", &controls.threads, 1, controls.max_threads);
      changed |= ImGui::Checkbox("shadows", &controls.shadows);
      changed |= ImGui::Checkbox("textures", &controls.textures);
      changed |= ImGui::Checkbox("watertight triangle test", &controls.watertight);
    }
  }
  ImGui::End();
  return changed;
}

}  // namespace sinew::demo

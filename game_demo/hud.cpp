#include "game_demo/hud.h"

#include <imgui.h>

#include <algorithm>

namespace sinew::demo {

void FrameRateMeter::add_frame(double milliseconds) {
  // About a half-second memory at 60 fps; the first frame seeds it.
  constexpr double kWeight = 0.05;
  smoothed_ms_ = smoothed_ms_ == 0.0 ? milliseconds : smoothed_ms_ + kWeight * (milliseconds - smoothed_ms_);
}

void HudControls::take(const SoftLighting& lighting) {
  const SoftLighting preset = soft_preset();
  soft_shadows = lighting.light_radius > 0.0f;
  ambient_occlusion = lighting.ao_rays > 0;
  soft = lighting;
  if (!soft_shadows) soft.light_radius = preset.light_radius;
  if (!ambient_occlusion) soft.ao_rays = preset.ao_rays;
}

SoftLighting HudControls::soft_lighting() const {
  SoftLighting lighting = soft;
  if (!soft_shadows) lighting.light_radius = 0.0f;
  if (!ambient_occlusion) lighting.ao_rays = 0;
  return lighting;
}

namespace {

// The soft-lighting toggles, each with its values while on. The sliders
// end where a game would: a light wider than the character is a sky, and
// more than 16 rays a hit is an offline render.
bool soft_lighting_controls(HudControls& controls) {
  constexpr int kMaxRays = 16;
  SoftLighting& soft = controls.soft;
  bool changed = ImGui::Checkbox("soft shadows", &controls.soft_shadows);
  if (controls.soft_shadows) {
    changed |= ImGui::SliderFloat("light radius (m)", &soft.light_radius, 0.05f, kCharacterHeight, "%.2f");
    changed |= ImGui::SliderInt("shadow samples", &soft.shadow_samples, 1, kMaxRays);
  }
  changed |= ImGui::Checkbox("ambient occlusion", &controls.ambient_occlusion);
  if (controls.ambient_occlusion) {
    changed |= ImGui::SliderInt("AO rays", &soft.ao_rays, 1, kMaxRays);
    changed |= ImGui::SliderFloat("AO radius (m)", &soft.ao_radius, 0.05f, 2.0f * kCharacterHeight, "%.2f");
  }
  // Typed values (ctrl+click) may leave a slider's range: keep what the
  // renderer takes.
  soft.light_radius = std::max(soft.light_radius, 0.0f);
  soft.shadow_samples = std::clamp(soft.shadow_samples, 1, rt::kMaxSamples);
  soft.ao_rays = std::clamp(soft.ao_rays, 1, rt::kMaxSamples);
  soft.ao_radius = std::max(soft.ao_radius, 0.01f);
  return changed;
}

}  // namespace

bool draw_hud(const HudFrame& frame, const BakeInfo& bake, HudControls& controls) {
  ImGui::SetNextWindowPos(ImVec2(8.0f, 8.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.75f);
  bool changed = false;
  if (ImGui::Begin("Sinew (F1 hides)", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
    ImGui::Text("%.1f fps   %dx%d", frame.fps, frame.width, frame.height);
    const double mrays = frame.trace_ms > 0.0 ? static_cast<double>(frame.rays) / (frame.trace_ms * 1e3) : 0.0;
    ImGui::Text("%.2f M rays/s traced (%.2f M rays)", mrays, static_cast<double>(frame.rays) * 1e-6);
    // What soft shadows and ambient occlusion cost, one under the other.
    ImGui::Text("shadow rays %.2f M in %.2f ms", static_cast<double>(frame.shadow_rays) * 1e-6, frame.shadow_ms);
    ImGui::Text("AO rays     %.2f M in %.2f ms", static_cast<double>(frame.ao_rays) * 1e-6, frame.ao_ms);
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
      changed |= soft_lighting_controls(controls);
    }
  }
  ImGui::End();
  return changed;
}

}  // namespace sinew::demo

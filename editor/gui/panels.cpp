#include "editor/gui/panels.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "editor/gui/widget_log.h"

namespace sinew::editor::gui {
namespace {

// The sliders' ends: more samples than this are for offline renders (the
// command line takes up to rt::kMaxSamples); a sun wider than this is no
// longer a sun.
constexpr int kMaxPanelSamples = 64;
constexpr float kMaxSunDegrees = 10.0f;

// Every widget goes through these, so the frame's WidgetLog (when asked
// for) holds all of them.
bool header(const PanelContext& ctx, const char* label, ImGuiTreeNodeFlags flags = 0) {
  const bool open = ImGui::CollapsingHeader(label, flags);
  log_last_item(ctx.widgets, label, WidgetKind::kHeader, ImGui::IsItemToggledOpen());
  return open;
}

bool button(const PanelContext& ctx, const char* label, bool small = false) {
  const bool pressed = small ? ImGui::SmallButton(label) : ImGui::Button(label);
  log_last_item(ctx.widgets, label, WidgetKind::kButton, pressed);
  return pressed;
}

// A value widget: `draw(label)` draws it and returns whether it changed.
template <typename Draw>
bool field(const PanelContext& ctx, const char* label, Draw&& draw) {
  const bool changed = draw(label);
  log_last_item(ctx.widgets, label, WidgetKind::kField, changed);
  return changed;
}

const char* clip_name(const character::Model& model, int index) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.clips.size()) return "(none)";
  return model.clips[static_cast<std::size_t>(index)].name().c_str();
}

// A combo over the model's clips; `allow_none` adds "(none)" as -1.
bool clip_combo(const PanelContext& ctx, const char* label, const character::Model& model, int& index,
                bool allow_none) {
  bool changed = false;
  const bool open = ImGui::BeginCombo(label, clip_name(model, index));
  log_last_item(ctx.widgets, label, WidgetKind::kField, false);
  if (open) {
    if (allow_none && ImGui::Selectable("(none)", index < 0)) {
      index = -1;
      changed = true;
    }
    for (int i = 0; i < static_cast<int>(model.clips.size()); ++i) {
      ImGui::PushID(i);
      if (ImGui::Selectable(clip_name(model, i), index == i)) {
        index = i;
        changed = true;
      }
      ImGui::PopID();
    }
    ImGui::EndCombo();
  }
  return changed;
}

void model_panel(PanelState& state, const PanelContext& ctx, PanelActions& actions) {
  if (!header(ctx, "Model", ImGuiTreeNodeFlags_DefaultOpen)) return;
  field(ctx, "path",
        [&](const char* l) { return ImGui::InputText(l, state.load_path.data(), state.load_path.size()); });
  if (button(ctx, "Load")) actions.load = true;
  if (!ctx.message.empty()) ImGui::TextWrapped("%s", ctx.message.c_str());
}

void clips_panel(PanelState& state, const PanelContext& ctx, PanelActions& actions) {
  if (ctx.model == nullptr || !header(ctx, "Clips", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const character::Model& model = *ctx.model;
  PosePlayer& player = *ctx.player;
  if (model.clips.empty()) {
    ImGui::TextUnformatted("no clips: rest pose");
    return;
  }
  bool cycles_changed = clip_combo(ctx, "clip", model, state.clip_a, false);
  cycles_changed |= clip_combo(ctx, "second clip", model, state.clip_b, true);
  if (state.clip_b >= 0) {
    cycles_changed |=
        field(ctx, "blend", [&](const char* l) { return ImGui::SliderFloat(l, &state.blend, 0.0f, 1.0f); });
  }
  if (cycles_changed) (void)player.set_cycles(state.clip_a, state.clip_b, state.blend);
  if (button(ctx, *ctx.playing ? "Pause" : "Play")) *ctx.playing = !*ctx.playing;
  ImGui::SameLine();
  float t = static_cast<float>(player.time());
  const float span = static_cast<float>(player.duration());
  // The slider spans one loop; playback keeps counting past it.
  float shown = span > 0.0f ? std::fmod(t, span) : 0.0f;
  if (field(ctx, "time", [&](const char* l) { return ImGui::SliderFloat(l, &shown, 0.0f, span, "%.2f s"); })) {
    *ctx.playing = false;
    (void)player.seek(static_cast<double>(shown));
  }
  ImGui::TextUnformatted("actions:");
  for (int i = 0; i < static_cast<int>(model.clips.size()); ++i) {
    ImGui::PushID(1000 + i);
    if (i % 3 != 0) ImGui::SameLine();
    if (button(ctx, clip_name(model, i), true)) actions.action_clip = i;
    ImGui::PopID();
  }
}

void overlay_panel(PanelState& state, const PanelContext& ctx) {
  if (ctx.model == nullptr || !header(ctx, "Overlay", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Viewport& viewport = *ctx.viewport;
  int mode = static_cast<int>(viewport.overlay);
  const char* names[] = {"none", "fuzzy boxes", "leaf heat map", "escaped triangles"};
  if (field(ctx, "overlay", [&](const char* l) { return ImGui::Combo(l, &mode, names, 4); })) {
    viewport.overlay = static_cast<Overlay>(mode);
  }
  const auto& joint_names = ctx.model->skeleton.names();
  const int bones = static_cast<int>(joint_names.size());
  const auto bone_slider = [&](const char* l) { return ImGui::SliderInt(l, &state.bone, 0, bones - 1); };
  if (bones > 0 && field(ctx, "bone", bone_slider)) {
    viewport.bone = static_cast<std::uint32_t>(state.bone);
  }
  if (bones > 0 && state.bone < bones) {
    const std::uint32_t b = static_cast<std::uint32_t>(state.bone);
    const std::uint32_t triangles = b < ctx.fuzzy.bone_trees.size() ? ctx.fuzzy.bone_trees[b].triangle_count : 0;
    ImGui::Text("%s: %u triangles", joint_names[b].c_str(), triangles);
  }
  field(ctx, "shadows", [&](const char* l) { return ImGui::Checkbox(l, &viewport.settings.shadows); });
  if (button(ctx, "Reframe camera")) viewport.request_reframe();
}

// Soft shadows and ambient occlusion for every light: shadow rays per hit
// towards each area light, and the occlusion rays with their reach. Lengths
// are offered up to multiples of the character's height, so the sliders
// suit a model in centimetres and one in metres alike.
void soft_lighting_fields(const PanelContext& ctx) {
  rt::RenderSettings& settings = ctx.viewport->settings;
  const float height = ctx.viewport->character_height();
  field(ctx, "shadow samples",
        [&](const char* l) { return ImGui::SliderInt(l, &settings.shadow_samples, 1, kMaxPanelSamples); });
  field(ctx, "AO rays", [&](const char* l) { return ImGui::SliderInt(l, &settings.ao_rays, 0, kMaxPanelSamples); });
  field(ctx, "AO radius", [&](const char* l) {
    return ImGui::SliderFloat(l, &settings.ao_radius, 0.01f * height, 2.0f * height, "%.3f");
  });
  // Typed values (ctrl+click) may leave a slider's range: keep what the
  // renderer takes.
  settings.shadow_samples = std::clamp(settings.shadow_samples, 1, rt::kMaxSamples);
  settings.ao_rays = std::clamp(settings.ao_rays, 0, rt::kMaxSamples);
  settings.ao_radius = std::max(settings.ao_radius, 1e-3f * height);
}

// A light's size, which makes it an area light with soft shadows: a point
// light's sphere radius (scene units), the sun's angular radius (degrees).
void light_size_field(const PanelContext& ctx, rt::Light& light) {
  if (light.kind == rt::Light::Kind::kDirectional) {
    float degrees = glm::degrees(light.angular_radius);
    if (field(ctx, "sun radius (deg)",
              [&](const char* l) { return ImGui::SliderFloat(l, &degrees, 0.0f, kMaxSunDegrees, "%.2f"); })) {
      light.angular_radius = glm::radians(std::clamp(degrees, 0.0f, kMaxSunDegrees));
    }
    return;
  }
  const float height = ctx.viewport->character_height();
  if (field(ctx, "radius", [&](const char* l) { return ImGui::SliderFloat(l, &light.radius, 0.0f, height, "%.3f"); })) {
    light.radius = std::max(light.radius, 0.0f);
  }
}

// The view's lights: each point or directional, its position or the
// direction towards it, its colour and its size; up to rt::kMaxLights, at
// least one; then the soft-lighting settings they share.
void lights_panel(const PanelContext& ctx) {
  if (ctx.model == nullptr || !header(ctx, "Lights")) return;
  std::vector<rt::Light>& lights = ctx.viewport->lights;
  const char* kinds[] = {"point", "directional"};
  std::size_t remove = lights.size();
  for (std::size_t i = 0; i < lights.size(); ++i) {
    rt::Light& light = lights[i];
    ImGui::PushID(static_cast<int>(i));
    ImGui::Text("light %zu", i + 1);
    int kind = light.kind == rt::Light::Kind::kDirectional ? 1 : 0;
    if (field(ctx, "kind", [&](const char* l) { return ImGui::Combo(l, &kind, kinds, 2); })) {
      light.kind = kind == 1 ? rt::Light::Kind::kDirectional : rt::Light::Kind::kPoint;
    }
    Vec3& where = kind == 1 ? light.direction : light.position;
    field(ctx, kind == 1 ? "towards" : "position",
          [&](const char* l) { return ImGui::DragFloat3(l, &where.x, 0.05f); });
    field(ctx, "colour", [&](const char* l) { return ImGui::ColorEdit3(l, &light.color.x, ImGuiColorEditFlags_Float); });
    light_size_field(ctx, light);
    if (lights.size() > 1 && button(ctx, "Remove light", true)) remove = i;
    ImGui::PopID();
  }
  if (remove < lights.size()) lights.erase(lights.begin() + static_cast<std::ptrdiff_t>(remove));
  if (lights.size() < rt::kMaxLights && button(ctx, "Add light")) {
    rt::Light added = lights.empty() ? rt::Light{} : lights.back();
    added.color = Vec3(0.5f);
    lights.push_back(added);
  }
  soft_lighting_fields(ctx);
}

void bake_panel(PanelState& state, const PanelContext& ctx, PanelActions& actions) {
  if (ctx.model == nullptr || !header(ctx, "Bake", ImGuiTreeNodeFlags_DefaultOpen)) return;
  int mode = static_cast<int>(state.bake.mode);
  const char* modes[] = {"arbitrary", "joint limits", "clips", "one clip"};
  if (field(ctx, "pose space", [&](const char* l) { return ImGui::Combo(l, &mode, modes, 4); })) {
    state.bake.mode = static_cast<anim::PoseSpaceMode>(mode);
  }
  if (state.bake.mode == anim::PoseSpaceMode::kClip) {
    clip_combo(ctx, "bake clip", *ctx.model, state.bake_clip, false);
    state.bake.clip = clip_name(*ctx.model, state.bake_clip);
  }
  field(ctx, "samples", [&](const char* l) { return ImGui::InputInt(l, &state.bake.samples); });
  state.bake.samples = std::max(0, state.bake.samples);
  field(ctx, "padding",
        [&](const char* l) { return ImGui::SliderFloat(l, &state.bake.padding, 0.0f, 0.1f, "%.3f"); });
  if (ctx.bake_running) {
    char label[64];
    std::snprintf(label, sizeof(label), "%s %.0f%%", ctx.bake_phase.c_str(), ctx.bake_progress * 100.0);
    ImGui::ProgressBar(static_cast<float>(ctx.bake_progress), ImVec2(-1.0f, 0.0f), label);
    if (button(ctx, "Cancel")) actions.cancel_bake = true;
  } else if (button(ctx, "Bake##start")) {
    // "##start" keeps the label and gives the button its own ID: the
    // header above is "Bake" too, and one ID for both swallows the click.
    actions.bake = true;
  }
  if (ctx.can_save_pack) {
    field(ctx, "pack",
          [&](const char* l) { return ImGui::InputText(l, state.pack_path.data(), state.pack_path.size()); });
    if (button(ctx, "Save as pack")) actions.save_pack = true;
  }
}

void limits_panel(PanelState& state, const PanelContext& ctx, PanelActions& actions) {
  if (ctx.model == nullptr || !header(ctx, "Joint limits")) return;
  const auto& names = ctx.model->skeleton.names();
  const int joints = static_cast<int>(names.size());
  if (joints == 0 || state.limits.size() != names.size()) return;
  state.joint = std::clamp(state.joint, 0, joints - 1);
  field(ctx, "joint", [&](const char* l) { return ImGui::SliderInt(l, &state.joint, 0, joints - 1); });
  ImGui::TextUnformatted(names[static_cast<std::size_t>(state.joint)].c_str());
  anim::JointLimit& limit = state.limits[static_cast<std::size_t>(state.joint)];
  bool euler = limit.kind == anim::LimitKind::kEuler;
  if (limit.kind == anim::LimitKind::kSwingTwist) ImGui::TextUnformatted("swing-twist limit (edit as Euler to replace)");
  if (field(ctx, "Euler limit", [&](const char* l) { return ImGui::Checkbox(l, &euler); })) {
    limit.kind = euler ? anim::LimitKind::kEuler : anim::LimitKind::kFree;
  }
  if (euler) {
    Vec3 min_deg = glm::degrees(limit.euler.min);
    Vec3 max_deg = glm::degrees(limit.euler.max);
    const auto slider = [](Vec3& v) {
      return [&v](const char* l) { return ImGui::SliderFloat3(l, &v.x, -180.0f, 180.0f, "%.0f"); };
    };
    if (field(ctx, "min (deg)", slider(min_deg))) {
      limit.euler.min = glm::radians(glm::min(min_deg, max_deg));
    }
    if (field(ctx, "max (deg)", slider(max_deg))) {
      limit.euler.max = glm::radians(glm::max(min_deg, max_deg));
    }
  }
  field(ctx, "limits file",
        [&](const char* l) { return ImGui::InputText(l, state.limits_path.data(), state.limits_path.size()); });
  if (button(ctx, "Save limits")) actions.save_limits = true;
}

void stats_panel(const PanelContext& ctx) {
  if (!header(ctx, "Stats", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const EditorStats& s = *ctx.stats;
  ImGui::Text("%.1f fps", s.fps);
  for (const auto& [name, ms] : s.phases_ms) ImGui::Text("  %-12s %7.2f ms", name.c_str(), ms);
  ImGui::Text("triangles %zu   bones %zu", s.triangles, s.bones);
  ImGui::Text("pose samples %u%s", s.pose_samples, s.from_pack ? " (pack)" : "");
  ImGui::Text("fuzzy area ratio %.2f", s.fuzzy_area_ratio);
  ImGui::Text("escaped triangles %zu", s.escaped_triangles);
  // The soft-lighting cost of the last frame, beside the rays it traced.
  ImGui::Text("shadow rays %llu   %.2f ms", static_cast<unsigned long long>(s.shadow_rays), s.trace_shadow_ms);
  ImGui::Text("AO rays %llu   %.2f ms", static_cast<unsigned long long>(s.ao_rays), s.trace_ao_ms);
}

}  // namespace

void copy_text(std::array<char, 512>& dst, const std::string& text) {
  std::snprintf(dst.data(), dst.size(), "%s", text.c_str());
}

void PanelState::reset_for(const character::Model& model, std::span<const anim::JointLimit> stored_limits) {
  clip_a = model.clips.empty() ? -1 : 0;
  clip_b = -1;
  blend = 0.0f;
  joint = 0;
  bake_clip = 0;
  limits.assign(model.skeleton.joint_count(), anim::JointLimit{});
  if (stored_limits.size() == limits.size()) limits.assign(stored_limits.begin(), stored_limits.end());
  if (load_path[0] == '\0') copy_text(load_path, model.source);
}

PanelActions draw_editor_panels(PanelState& state, const PanelContext& ctx, float x, float height) {
  PanelActions actions;
  const ImGuiViewport* main = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(ImVec2(x, 0.0f), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(main->Size.x - x, height), ImGuiCond_Always);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;
  if (ImGui::Begin("Sinew editor", nullptr, flags)) {
    model_panel(state, ctx, actions);
    clips_panel(state, ctx, actions);
    overlay_panel(state, ctx);
    lights_panel(ctx);
    bake_panel(state, ctx, actions);
    limits_panel(state, ctx, actions);
    stats_panel(ctx);
  }
  ImGui::End();
  return actions;
}

}  // namespace sinew::editor::gui

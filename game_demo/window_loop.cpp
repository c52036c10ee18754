#include "game_demo/window_loop.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "game_demo/controls.h"
#include "game_demo/hud.h"
#include "runtime/display/imgui_layer.h"
#include "runtime/display/pixel_display.h"

namespace sinew::demo {
namespace {

KeySnapshot keyboard_keys(const Window& window, bool imgui_has_keyboard) {
  KeySnapshot keys;
  if (imgui_has_keyboard) return keys;  // typing into a panel does not move the player
  auto any = [&](int a, int b) { return window.key_down(a) || (b != GLFW_KEY_UNKNOWN && window.key_down(b)); };
  keys.set(DemoKey::kForward, any(GLFW_KEY_W, GLFW_KEY_UP));
  keys.set(DemoKey::kBack, any(GLFW_KEY_S, GLFW_KEY_DOWN));
  keys.set(DemoKey::kLeft, any(GLFW_KEY_A, GLFW_KEY_LEFT));
  keys.set(DemoKey::kRight, any(GLFW_KEY_D, GLFW_KEY_RIGHT));
  keys.set(DemoKey::kRun, any(GLFW_KEY_LEFT_SHIFT, GLFW_KEY_RIGHT_SHIFT));
  keys.set(DemoKey::kTurnLeft, any(GLFW_KEY_Q, GLFW_KEY_UNKNOWN));
  keys.set(DemoKey::kTurnRight, any(GLFW_KEY_E, GLFW_KEY_UNKNOWN));
  keys.set(DemoKey::kAction, any(GLFW_KEY_SPACE, GLFW_KEY_UNKNOWN));
  keys.set(DemoKey::kNextCharacter, any(GLFW_KEY_TAB, GLFW_KEY_UNKNOWN));
  keys.set(DemoKey::kToggleHud, any(GLFW_KEY_F1, GLFW_KEY_UNKNOWN));
  keys.set(DemoKey::kQuit, any(GLFW_KEY_ESCAPE, GLFW_KEY_UNKNOWN));
  return keys;
}

// Mouse look: dragging with the left button turns and tilts the camera.
class MouseLook {
 public:
  void update(const Window& window, bool imgui_has_mouse, FollowCamera& camera) {
    double x = 0.0, y = 0.0;
    window.cursor_position(&x, &y);
    const bool dragging = !imgui_has_mouse && window.mouse_button_down(GLFW_MOUSE_BUTTON_LEFT);
    if (dragging && was_dragging_) {
      constexpr double kRadiansPerPixel = 0.005;
      camera.yaw += static_cast<float>((x - last_x_) * kRadiansPerPixel);
      camera.pitch = std::clamp(camera.pitch + static_cast<float>((y - last_y_) * kRadiansPerPixel), 0.05f, 1.4f);
    }
    was_dragging_ = dragging;
    last_x_ = x;
    last_y_ = y;
  }

 private:
  bool was_dragging_ = false;
  double last_x_ = 0.0;
  double last_y_ = 0.0;
};

HudFrame hud_frame(const DemoSession& session, const FrameReport& report, const PhaseTimers& timers, double fps) {
  HudFrame h;
  h.fps = fps;
  h.phases_ms = timers.latest();
  const rt::RenderStats& r = report.render;
  h.rays = r.primary_rays + r.shadow_rays + r.ao_rays;
  h.trace_ms = r.trace_primary_ms + r.trace_shadow_ms + r.trace_ao_ms;
  h.shadow_rays = r.shadow_rays;
  h.shadow_ms = r.trace_shadow_ms;
  h.ao_rays = r.ao_rays;
  h.ao_ms = r.trace_ao_ms;
  h.characters = session.world().character_count();
  h.player = session.world().player();
  h.per_character = per_character_cost(h.phases_ms, h.characters);
  h.escaped_triangles = report.scene.escaped_triangles;
  h.fallback_ms = report.scene.fallback_ms;
  h.width = session.width();
  h.height = session.height();
  return h;
}

}  // namespace

Expected<WindowRunResult> run_window(DemoSession& session, std::unique_ptr<JobSystem>& jobs, Window& window,
                                     const WindowRunOptions& options) {
  SINEW_ASSIGN_OR_RETURN(std::unique_ptr<ImGuiLayer> imgui, ImGuiLayer::create(window));
  PixelDisplay display;
  FollowCamera camera;
  MouseLook mouse;
  FrameRateMeter meter;
  HudControls controls;
  controls.threads = jobs->thread_count();
  controls.max_threads = std::max<int>(jobs->thread_count(), static_cast<int>(std::thread::hardware_concurrency()));
  controls.shadows = session.render_settings().shadows;
  controls.textures = session.render_settings().textures;
  controls.watertight = session.render_settings().triangle_test == rt::TriangleTest::kWatertight;
  controls.take(session.soft_lighting());
  bool hud = options.hud;
  KeySnapshot previous_keys;
  WindowRunResult result;
  auto last = std::chrono::steady_clock::now();
  while (!window.should_close() && (options.frames == 0 || result.frames < options.frames)) {
    window.poll_events();
    const auto now = std::chrono::steady_clock::now();
    const double wall_ms = std::chrono::duration<double, std::milli>(now - last).count();
    last = now;
    ControlResult control;
    float dt = kScriptStepSeconds;
    if (options.script != nullptr) {
      control = script_controls(*options.script, result.frames, camera);
    } else {
      dt = std::min(0.1f, static_cast<float>(wall_ms * 1e-3));
      const KeySnapshot keys = keyboard_keys(window, imgui->wants_keyboard());
      mouse.update(window, imgui->wants_mouse(), camera);
      control = apply_controls(keys, previous_keys, dt, camera);
      previous_keys = keys;
    }
    if (control.quit) break;
    if (control.toggle_hud) hud = !hud;
    if (result.frames > 0) meter.add_frame(wall_ms);

    SINEW_ASSIGN_OR_RETURN(const FrameReport report, session.frame(dt, control.input, camera, *jobs));
    int vw = 0, vh = 0;
    window.framebuffer_size(&vw, &vh);
    {
      ScopedPhase phase(session.timers(), "display");
      SINEW_RETURN_IF_ERROR(display.present(session.width(), session.height(), session.rgba(), vw, vh));
      imgui->begin_frame();
      if (hud && draw_hud(hud_frame(session, report, session.timers(), meter.fps()), session.bake_info(), controls)) {
        session.render_settings().shadows = controls.shadows;
        session.render_settings().textures = controls.textures;
        session.render_settings().triangle_test =
            controls.watertight ? rt::TriangleTest::kWatertight : rt::TriangleTest::kFast;
        session.set_soft_lighting(controls.soft_lighting());
        if (controls.threads != jobs->thread_count()) jobs = std::make_unique<JobSystem>(controls.threads);
      }
      imgui->end_frame();
      if (options.keep_last_shown) {
        result.last_shown = window.read_back_buffer(&result.shown_width, &result.shown_height);
      }
      window.swap_buffers();
    }
    ++result.frames;
  }
  return result;
}

}  // namespace sinew::demo

#include "game_demo/controls.h"

#include <array>
#include <utility>

namespace sinew::demo {

std::optional<DemoKey> demo_key_from_name(std::string_view name) {
  static constexpr std::array<std::pair<std::string_view, DemoKey>, 15> kNames{{
      {"w", DemoKey::kForward},
      {"up", DemoKey::kForward},
      {"s", DemoKey::kBack},
      {"down", DemoKey::kBack},
      {"a", DemoKey::kLeft},
      {"left", DemoKey::kLeft},
      {"d", DemoKey::kRight},
      {"right", DemoKey::kRight},
      {"shift", DemoKey::kRun},
      {"q", DemoKey::kTurnLeft},
      {"e", DemoKey::kTurnRight},
      {"space", DemoKey::kAction},
      {"tab", DemoKey::kNextCharacter},
      {"f1", DemoKey::kToggleHud},
      {"esc", DemoKey::kQuit},
  }};
  for (const auto& [key_name, key] : kNames) {
    if (key_name == name) return key;
  }
  return std::nullopt;
}

ControlResult apply_controls(const KeySnapshot& now, const KeySnapshot& before, float dt,
                             FollowCamera& camera) {
  auto axis = [&](DemoKey plus, DemoKey minus) {
    return (now.down(plus) ? 1.0f : 0.0f) - (now.down(minus) ? 1.0f : 0.0f);
  };
  auto pressed = [&](DemoKey key) { return now.down(key) && !before.down(key); };
  camera.yaw += axis(DemoKey::kTurnRight, DemoKey::kTurnLeft) * kCameraTurnRate * dt;
  ControlResult r;
  r.input.forward = axis(DemoKey::kForward, DemoKey::kBack);
  r.input.right = axis(DemoKey::kRight, DemoKey::kLeft);
  r.input.run = now.down(DemoKey::kRun);
  r.input.action = pressed(DemoKey::kAction);
  r.input.next_character = pressed(DemoKey::kNextCharacter);
  r.input.camera_yaw = camera.yaw;
  r.toggle_hud = pressed(DemoKey::kToggleHud);
  r.quit = now.down(DemoKey::kQuit);
  return r;
}

}  // namespace sinew::demo

// The demo's controls, independent of where key states come from: the
// window's keyboard or a recorded input script (input_script.h). One
// mapping serves both, so a scripted window run and a scripted headless run
// step the world identically — which is what the window test relies on.
#pragma once

#include <bitset>
#include <cstddef>
#include <optional>
#include <string_view>

#include "game_demo/demo_session.h"
#include "game_demo/world.h"

namespace sinew::demo {

// Logical keys. Aliases (W and Up, S and Down, ...) are one control each.
enum class DemoKey : std::size_t {
  kForward,      // W, Up
  kBack,         // S, Down
  kLeft,         // A, Left
  kRight,        // D, Right
  kRun,          // Shift
  kTurnLeft,     // Q
  kTurnRight,    // E
  kAction,       // Space
  kNextCharacter,  // Tab
  kToggleHud,    // F1
  kQuit,         // Esc
  kCount,
};

class KeySnapshot {
 public:
  bool down(DemoKey key) const { return bits_[static_cast<std::size_t>(key)]; }
  void set(DemoKey key, bool down) { bits_[static_cast<std::size_t>(key)] = down; }
  bool operator==(const KeySnapshot&) const = default;

 private:
  std::bitset<static_cast<std::size_t>(DemoKey::kCount)> bits_;
};

// A key's script name ("w", "up", "shift", "f1", "esc", ...), or nullopt.
std::optional<DemoKey> demo_key_from_name(std::string_view name);

// What one frame's keys ask of the game beyond the player's input.
struct ControlResult {
  PlayerInput input;  // input.camera_yaw is the camera's yaw after turning
  bool toggle_hud = false;
  bool quit = false;
};

// Camera turn rate of Q / E, radians per second.
inline constexpr float kCameraTurnRate = 2.0f;

// Maps this frame's keys (`now`, and `before` for press edges: Space, Tab
// and F1 act once per press) to the player's input, and turns `camera` by
// Q / E over dt seconds.
ControlResult apply_controls(const KeySnapshot& now, const KeySnapshot& before, float dt,
                             FollowCamera& camera);

}  // namespace sinew::demo

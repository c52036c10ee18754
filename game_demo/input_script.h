// A recorded input script: which keys are down on which frame, for
// deterministic runs of the window (the Xvfb test) and of the headless demo.
// Text, one event per line, '#' starts a comment:
//
//   # frame  key    event
//   0        w      down
//   30       shift  down      # run from frame 30
//   60       shift  up
//   75       space  tap       # down on frame 75, up on frame 76
//   100      esc    tap       # quit
//
// Keys: w a s d, up down left right, shift, q e, space, tab, f1, esc (aliases
// such as w and up are the same control). Events: down, up, tap. Events
// apply in frame order; lines with the same frame apply in file order.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "game_demo/controls.h"
#include "runtime/core/expected.h"

namespace sinew::demo {

class InputScript {
 public:
  // Errors (kInvalidData) name the source, the line and the bad token.
  static Expected<InputScript> parse(std::string_view text, const std::string& source);
  // Errors: kIoError when the file cannot be read; parse errors as above.
  static Expected<InputScript> load(const std::string& path);

  // The keys held on `frame` (frames before 0 have nothing held).
  KeySnapshot keys_at(int frame) const;
  // The last frame any event touches (a tap's release included); -1 when empty.
  int last_frame() const;

 private:
  struct Event {
    int frame = 0;
    DemoKey key = DemoKey::kForward;
    bool down = false;
  };
  std::vector<Event> events_;  // sorted by frame, stable
};

}  // namespace sinew::demo

namespace sinew::demo {

// Fixed step of scripted runs (headless and windowed alike), seconds.
inline constexpr float kScriptStepSeconds = 1.0f / 30.0f;

// The controls of `frame` of a script: its keys against the previous
// frame's, over one fixed step.
ControlResult script_controls(const InputScript& script, int frame, FollowCamera& camera);

}  // namespace sinew::demo

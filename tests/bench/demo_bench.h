// sinew-bench demo: the game demo's frame rate and per-phase breakdown for
// several character counts, through the demo's own session (the arena,
// the wandering characters, shadows) and its scripted player.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "demo"; returns 0, 1 (the session failed)
// or 2 (usage error).
int run_demo_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

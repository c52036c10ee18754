// sinew-bench memory: what each added character instance costs in resident
// memory. One character is loaded through the public API; instances of it
// are added to a World in steps (1, 2, 4, ... by default), each step
// animated and rendered one small frame, and the process's resident set
// read after it. Each step's growth per added instance is set against the
// instance's skinned vertices (as the runtime stores them) plus 4 KiB: the
// pose, the skinned vertices and a share of the top level, never baked data.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "memory"; returns 0, 1 (a failure) or 2
// (usage error).
int run_memory_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

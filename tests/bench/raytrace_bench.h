// sinew-bench raytrace: per-phase frame times of the fuzzy-kd-tree ray
// tracer (animation, skinning, bone boxes, top level, tracing, shading) for
// each model x instance count x thread count, and, in the same run, the
// trace time of an exact SAH kd-tree rebuilt over the same skinned triangles
// (the quality of the fuzzy structure; the paper reports about 2x).
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "raytrace"; `command_line` is the whole
// command as typed, printed in the report so a table can be reproduced.
// Returns the exit code: 0, 1 (a model failed to load, bake or render) or 2
// (usage error).
int run_raytrace_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

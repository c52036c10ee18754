// sinew-bench structures: the fuzzy structures side by side (issue 19's
// table; docs/RAYTRACE.md "Pose-space clusters"): the paper's one tree a
// bone against K pose-space clusters a bone, on Cally at each subdivision
// level and on the other models of shared/content. Per model and
// structure: pack size, bake time, fuzzy area, per-frame update, triangle
// tests and node visits per ray (primary and shadow), frame time, and the
// memory a frame holds per instance.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

int run_structures_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

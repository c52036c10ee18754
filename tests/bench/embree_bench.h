// sinew-bench embree: the peer comparison against Intel Embree 3, in one
// process and one run: Sinew's fuzzy bone trees (the real per-frame path),
// Embree rebuilt per frame at LOW and at MEDIUM quality, Embree refitted per
// frame, and an exact SAH kd-tree of Sinew's rebuilt per frame, all over the
// same skinned triangles (Sinew's own skinning, a shared phase), the same
// camera rays, shadow rays and shading, alternating frame by frame. A
// contender whose first frame disagrees with brute force is not reported.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// The name of Sinew's row in the tables and the JSON (the report reads it).
inline constexpr const char* kSinewContender = "sinew fuzzy";

// `args` are the arguments after "embree". Returns 0, 1 (a model failed to
// load or a contender failed its brute-force check) or 2 (usage error).
int run_embree_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

// sinew-bench animation: per-instance animation cost and skinning throughput
// for Cally and the mannequin at 1, 10 and 100 instances, beside the same
// work done by the Cal3D library in the same run (docs/ANIMATION.md, "Benchmark").
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

int run_animation_bench(const std::vector<std::string>& args);

}  // namespace sinew::bench

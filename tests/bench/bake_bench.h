// sinew-bench bake: the fuzzy bake's cost and quality per candidate-bone
// mode (all bones, the paper's choice, vs the influencing bones and their
// parents/children), on Cally and the mannequin, and its memory bound on a
// synthetic 300k-triangle x 60-bone character.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// `args` are the arguments after "bake"; returns 0, 1 (a model failed to
// load or bake) or 2 (usage error).
int run_bake_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

// sinew-bench paper: reproduces Tables 1 and 2 of Günther et al. 2006 on
// Sinew (pose space vs fuzzy area and fps; preprocessing and fps vs mesh
// size), printing the paper's rows beside Sinew's.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

// Exit codes: 0 ok; 1 a model failed to load, a bake failed, or a
// configuration failed its brute-force check; 2 usage error.
int run_paper_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

// sinew-bench paper: placeholder, being written.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

int run_paper_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

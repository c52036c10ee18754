// sinew-bench tradeoff: placeholder, being written.
#pragma once

#include <string>
#include <vector>

namespace sinew::bench {

int run_tradeoff_bench(const std::vector<std::string>& args, const std::string& command_line);

}  // namespace sinew::bench

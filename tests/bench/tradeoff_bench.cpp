#include "tests/bench/tradeoff_bench.h"

#include <cstdio>

namespace sinew::bench {

int run_tradeoff_bench(const std::vector<std::string>& /*args*/, const std::string& /*command_line*/) {
  std::fprintf(stderr, "sinew-bench tradeoff: not written yet\n");
  return 2;
}

}  // namespace sinew::bench

#include "tests/bench/paper_bench.h"

#include <cstdio>

namespace sinew::bench {

int run_paper_bench(const std::vector<std::string>& /*args*/, const std::string& /*command_line*/) {
  std::fprintf(stderr, "sinew-bench paper: not written yet\n");
  return 2;
}

}  // namespace sinew::bench
